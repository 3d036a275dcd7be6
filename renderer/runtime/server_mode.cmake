# pvr-node-server: the server mode of pvr-node (server_mode.cpp) as its own
# executable, placed next to pvrd (pvrd's default --node). Included from
# pvrd/CMakeLists.txt so that renderer/runtime/CMakeLists.txt stays with the
# batch program.
add_library(pvr_server_mode STATIC ${CMAKE_SOURCE_DIR}/renderer/runtime/server_mode.cpp)
target_include_directories(pvr_server_mode PUBLIC ${CMAKE_SOURCE_DIR}/renderer/runtime)
target_compile_definitions(pvr_server_mode PUBLIC OMPI_SKIP_MPICXX=1 MPICH_SKIP_MPICXX=1)
target_link_libraries(pvr_server_mode PUBLIC pvr_core pvr_protocol MPI::MPI_C PRIVATE ZLIB::ZLIB)
add_executable(pvr-node-server ${CMAKE_SOURCE_DIR}/renderer/runtime/pvr_node_server_main.cpp)
target_link_libraries(pvr-node-server PRIVATE pvr_server_mode MPI::MPI_C)
set_target_properties(pvr-node-server PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/pvrd)
