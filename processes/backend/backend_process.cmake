# traverse-backend: the backend process (seed 000: correlative matching, best-of-candidates loop
# closure, SPA; seed 004: marginals). The algorithm is traverse_backend_slam, without LCM (tests
# link it directly); the node adapts messages; the program runs the node in the process loop.
add_library(traverse_backend_slam STATIC
  ${CMAKE_CURRENT_LIST_DIR}/correlative_matcher.cpp ${CMAKE_CURRENT_LIST_DIR}/scan_store.cpp
  ${CMAKE_CURRENT_LIST_DIR}/scan_refiner.cpp ${CMAKE_CURRENT_LIST_DIR}/loop_closer.cpp
  ${CMAKE_CURRENT_LIST_DIR}/frontend_chain.cpp ${CMAKE_CURRENT_LIST_DIR}/odometry_check.cpp
  ${CMAKE_CURRENT_LIST_DIR}/boresight.cpp ${CMAKE_CURRENT_LIST_DIR}/start_frame.cpp
  ${CMAKE_CURRENT_LIST_DIR}/backend.cpp ${CMAKE_CURRENT_LIST_DIR}/key_link.cpp
  ${CMAKE_CURRENT_LIST_DIR}/backend_state.cpp)
target_link_libraries(traverse_backend_slam PUBLIC traverse_backend)

add_library(traverse_backend_node STATIC ${CMAKE_CURRENT_LIST_DIR}/backend_node.cpp)
target_link_libraries(traverse_backend_node PUBLIC traverse_backend_slam traverse_common)

add_executable(traverse-backend ${CMAKE_CURRENT_LIST_DIR}/backend_main.cpp)
target_link_libraries(traverse-backend PRIVATE traverse_backend_node)
