# npm_ci(TARGET SOURCE_DIR OUT_DIR FILES): copies FILES and SOURCE_DIR's package.json and
# package-lock.json into OUT_DIR and installs the packages the lock file pins there with `npm ci`
# (again whenever the lock file changes). The packages come from the npm registry at build time;
# nothing of them is kept in the repository. When the registry cannot be reached the build stops
# and says so (cmake/npm_ci_run.cmake).
find_program(NPM_EXECUTABLE npm)
if(NOT NPM_EXECUTABLE)
  message(FATAL_ERROR "npm not found: the viewer's page (three.js) and its browser test "
    "(playwright-core) are installed from the npm registry at build time; scripts/setup.sh "
    "installs Node.js and npm")
endif()

function(npm_ci target source_dir out_dir files)
  set(outputs "")
  foreach(f ${files} ${source_dir}/package.json ${source_dir}/package-lock.json)
    get_filename_component(name ${f} NAME)
    add_custom_command(OUTPUT ${out_dir}/${name}
      COMMAND ${CMAKE_COMMAND} -E copy ${f} ${out_dir}/${name}
      DEPENDS ${f} COMMENT "copying ${name} into ${out_dir}")
    list(APPEND outputs ${out_dir}/${name})
  endforeach()
  set(stamp ${out_dir}/node_modules/.npm-ci-stamp)
  add_custom_command(OUTPUT ${stamp}
    COMMAND ${CMAKE_COMMAND} -DNPM=${NPM_EXECUTABLE} -DDIR=${out_dir} -DSTAMP=${stamp}
      -P ${CMAKE_SOURCE_DIR}/cmake/npm_ci_run.cmake
    DEPENDS ${out_dir}/package.json ${out_dir}/package-lock.json
      ${CMAKE_SOURCE_DIR}/cmake/npm_ci_run.cmake
    COMMENT "npm ci in ${out_dir} (packages from the npm registry)")
  add_custom_target(${target} ALL DEPENDS ${outputs} ${stamp})
endfunction()
