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
set(LCM_PY_OUT ${CMAKE_BINARY_DIR}/python)
set(LCM_PY_FILES "")
foreach(f ${LCM_FILES})
  get_filename_component(type ${f} NAME_WE)
  list(APPEND LCM_PY_FILES ${LCM_PY_OUT}/traverse/${type}.py)
endforeach()
add_custom_command(
  OUTPUT ${LCM_PY_FILES}
  COMMAND ${CMAKE_COMMAND} -E make_directory ${LCM_PY_OUT}
  COMMAND ${LCM_GEN} --python --ppath ${LCM_PY_OUT} ${LCM_FILES}
  DEPENDS ${LCM_FILES}
  COMMENT "lcm-gen: generating Python message types")
add_custom_target(lcmtypes_python ALL DEPENDS ${LCM_PY_FILES})

find_package(Java COMPONENTS Development)
find_file(LCM_JAR lcm.jar PATHS /usr/share/java /usr/local/share/java)
if(Java_FOUND AND LCM_JAR)
  include(UseJava)
  set(LCM_JAVA_SRC ${CMAKE_BINARY_DIR}/java/src)
  set(LCM_JAVA_FILES "")
  foreach(f ${LCM_FILES})
    get_filename_component(type ${f} NAME_WE)
    list(APPEND LCM_JAVA_FILES ${LCM_JAVA_SRC}/traverse/${type}.java)
  endforeach()
  add_custom_command(
    OUTPUT ${LCM_JAVA_FILES}
    COMMAND ${CMAKE_COMMAND} -E make_directory ${LCM_JAVA_SRC}
    COMMAND ${LCM_GEN} --java --jpath ${LCM_JAVA_SRC} ${LCM_FILES}
    DEPENDS ${LCM_FILES}
    COMMENT "lcm-gen: generating Java message types")
  add_jar(traverse_lcmtypes_java SOURCES ${LCM_JAVA_FILES} INCLUDE_JARS ${LCM_JAR}
    OUTPUT_NAME traverse-lcmtypes OUTPUT_DIR ${CMAKE_BINARY_DIR}/java)
else()
  message(STATUS "No Java compiler or lcm.jar (liblcm-java): no Java message types, no lcm-spy")
endif()
