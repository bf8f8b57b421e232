# Generates C++ headers for every lcmtypes/*.lcm into the build tree (never committed), and a
# registry that maps each type's fingerprint to a decode check (used by traverse-validate).
file(GLOB LCM_FILES CONFIGURE_DEPENDS ${CMAKE_SOURCE_DIR}/lcmtypes/*.lcm)
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
add_custom_command(
  OUTPUT ${LCM_HEADERS}
  COMMAND ${CMAKE_COMMAND} -E make_directory ${LCM_OUT}
  COMMAND ${LCM_GEN} --cpp --cpp-hpath ${LCM_OUT} ${LCM_FILES}
  DEPENDS ${LCM_FILES}
  COMMENT "lcm-gen: generating C++ message types")
add_custom_target(lcmtypes_gen DEPENDS ${LCM_HEADERS})
configure_file(${CMAKE_SOURCE_DIR}/cmake/type_registry.cpp.in ${CMAKE_BINARY_DIR}/generated/type_registry.cpp @ONLY)
add_library(traverse_lcmtypes STATIC ${CMAKE_BINARY_DIR}/generated/type_registry.cpp)
add_dependencies(traverse_lcmtypes lcmtypes_gen)
# Generated code is not ours to warn about: include it as a system directory.
target_include_directories(traverse_lcmtypes SYSTEM PUBLIC ${LCM_OUT})
target_include_directories(traverse_lcmtypes PRIVATE ${CMAKE_SOURCE_DIR}/common)
target_link_libraries(traverse_lcmtypes PUBLIC lcm::lcm)
