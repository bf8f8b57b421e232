# Generates C++ headers for every lcmtypes/*.lcm into the build tree (never committed), and a
# registry that maps each type's fingerprint to a decode check (used by traverse-validate) and to
# the type's layout, taken from lcm-gen's own parse of the files (`lcm-gen -d`), so that a
# message's bytes can be checked against every length it claims before it is decoded
# (common/message_layout.hpp).
file(GLOB LCM_FILES CONFIGURE_DEPENDS ${CMAKE_SOURCE_DIR}/lcmtypes/*.lcm)
set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${LCM_FILES})
set(LCM_OUT ${CMAKE_BINARY_DIR}/lcmtypes)
set(LCM_HEADERS "")
set(registry_includes "")
set(registry_entries "")
foreach(f ${LCM_FILES})
  get_filename_component(type ${f} NAME_WE)
  list(APPEND LCM_HEADERS ${LCM_OUT}/traverse/${type}.hpp)
  string(APPEND registry_includes "#include \"traverse/${type}.hpp\"\n")
  string(APPEND registry_entries "      entry<traverse::${type}>(\"traverse.${type}\"),\n")
endforeach()
execute_process(COMMAND ${LCM_GEN} -d ${LCM_FILES} OUTPUT_VARIABLE registry_layouts
  RESULT_VARIABLE lcm_gen_rc)
if(NOT lcm_gen_rc EQUAL 0)
  message(FATAL_ERROR "lcm-gen -d failed on lcmtypes/*.lcm")
endif()
add_custom_command(
  OUTPUT ${LCM_HEADERS}
  COMMAND ${CMAKE_COMMAND} -E make_directory ${LCM_OUT}
  COMMAND ${LCM_GEN} --cpp --cpp-hpath ${LCM_OUT} ${LCM_FILES}
  DEPENDS ${LCM_FILES}
  COMMENT "lcm-gen: generating C++ message types")
add_custom_target(lcmtypes_gen DEPENDS ${LCM_HEADERS})
configure_file(${CMAKE_SOURCE_DIR}/cmake/type_registry.cpp.in ${CMAKE_BINARY_DIR}/generated/type_registry.cpp @ONLY)
add_library(traverse_lcmtypes STATIC ${CMAKE_BINARY_DIR}/generated/type_registry.cpp
  ${CMAKE_SOURCE_DIR}/common/message_layout.cpp ${CMAKE_SOURCE_DIR}/common/message_checks.cpp)
add_dependencies(traverse_lcmtypes lcmtypes_gen)
# Generated code is not ours to warn about: include it as a system directory.
target_include_directories(traverse_lcmtypes SYSTEM PUBLIC ${LCM_OUT})
target_include_directories(traverse_lcmtypes PRIVATE ${CMAKE_SOURCE_DIR}/common)
target_link_libraries(traverse_lcmtypes PUBLIC lcm::lcm)

# The same types for Python (build/python/traverse/, for analysis scripts: LCM 1.3.1 in Debian has
# no Python module, scripts/lcmlog.py reads logs) and Java (build/java/traverse-lcmtypes.jar, for
# lcm-spy: scripts/spy.sh), so that every tool decodes every channel.
# lcm_gen_language(LANG PATH_FLAG DIR EXT OUT_VAR): lcm-gen --LANG into DIR/traverse/*.EXT;
# the generated files' list in OUT_VAR.
function(lcm_gen_language lang path_flag dir ext out_var)
  set(files "")
  foreach(f ${LCM_FILES})
    get_filename_component(type ${f} NAME_WE)
    list(APPEND files ${dir}/traverse/${type}.${ext})
  endforeach()
  add_custom_command(
    OUTPUT ${files}
    COMMAND ${CMAKE_COMMAND} -E make_directory ${dir}
    COMMAND ${LCM_GEN} --${lang} ${path_flag} ${dir} ${LCM_FILES}
    DEPENDS ${LCM_FILES}
    COMMENT "lcm-gen: generating ${lang} message types")
  set(${out_var} ${files} PARENT_SCOPE)
endfunction()

lcm_gen_language(python --ppath ${CMAKE_BINARY_DIR}/python py LCM_PY_FILES)
add_custom_target(lcmtypes_python ALL DEPENDS ${LCM_PY_FILES})

find_package(Java COMPONENTS Development)
find_file(LCM_JAR lcm.jar PATHS /usr/share/java /usr/local/share/java)
if(Java_FOUND AND LCM_JAR)
  include(UseJava)
  lcm_gen_language(java --jpath ${CMAKE_BINARY_DIR}/java/src java LCM_JAVA_FILES)
  add_jar(traverse_lcmtypes_java SOURCES ${LCM_JAVA_FILES} INCLUDE_JARS ${LCM_JAR}
    OUTPUT_NAME traverse-lcmtypes OUTPUT_DIR ${CMAKE_BINARY_DIR}/java)
else()
  message(STATUS "No Java compiler or lcm.jar (liblcm-java): no Java message types, no lcm-spy")
endif()
