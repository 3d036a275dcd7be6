# The distributed frame under real mpirun: one driver per rank count that
# loops over strategies x decompositions x views inside a single job (MPI
# start-up costs ~0.5 s per job), and pvr-node --batch against pvr-render.
if(TARGET pvr_comm_mpi AND TARGET pvr-node)
  add_executable(pvr_node_mpi_driver mpi_driver.cpp steering_checks.cpp)
  target_link_libraries(pvr_node_mpi_driver PRIVATE pvr_node_frame pvr_node_computations pvr_image_io pvr_comm_mpi ZLIB::ZLIB)
  set(PVR_MPI_ENV OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1)
  set(PVR_MPIRUN ${MPIEXEC_EXECUTABLE} --oversubscribe --bind-to none)
  set(PVR_MPI_SCRATCH ${CMAKE_CURRENT_BINARY_DIR}/scratch)

  # Every strategy x decomposition x view, one job per rank count.
  foreach(ranks RANGE 1 8)
    add_test(NAME "node mpi: ${ranks} ranks equal the single-process render"
             COMMAND ${PVR_MPIRUN} -np ${ranks} $<TARGET_FILE:pvr_node_mpi_driver>
                     matrix ${PVR_MPI_SCRATCH}/matrix-${ranks})
    set_tests_properties("node mpi: ${ranks} ranks equal the single-process render"
                         PROPERTIES ENVIRONMENT "${PVR_MPI_ENV}" TIMEOUT 240 PROCESSORS 2)
  endforeach()

  # The steering example (node/computations/gray_scott.cpp) over 1..4 ranks
  # equals a serial run of the same steps, steered or not.
  foreach(ranks RANGE 1 4)
    add_test(NAME "node mpi: ${ranks} ranks of the Gray-Scott computation equal the serial run"
             COMMAND ${PVR_MPIRUN} -np ${ranks} $<TARGET_FILE:pvr_node_mpi_driver>
                     steering ${PVR_MPI_SCRATCH}/steering-${ranks})
    set_tests_properties("node mpi: ${ranks} ranks of the Gray-Scott computation equal the serial run"
                         PROPERTIES ENVIRONMENT "${PVR_MPI_ENV}" TIMEOUT 60 PROCESSORS 2)
  endforeach()

  # One rank's brick read throws: all fail alike, nothing deadlocks.
  foreach(ranks 3 4)
    add_test(NAME "node mpi: ${ranks} ranks fail together when one rank's brick is bad"
             COMMAND ${PVR_MPIRUN} -np ${ranks} $<TARGET_FILE:pvr_node_mpi_driver>
                     failure ${PVR_MPI_SCRATCH}/failure-${ranks})
    set_tests_properties("node mpi: ${ranks} ranks fail together when one rank's brick is bad"
                         PROPERTIES ENVIRONMENT "${PVR_MPI_ENV}" TIMEOUT 60 PROCESSORS 2)
  endforeach()

  # Ranks all on this host talk through the ob1 PML (shared memory), unless
  # the user named a PML (mpi_communicator.cpp, preferSharedMemoryOnOneHost).
  add_test(NAME "node mpi: ranks on one host use the ob1 PML"
           COMMAND ${PVR_MPIRUN} -np 2 $<TARGET_FILE:pvr_node_mpi_driver> pml)
  set_tests_properties("node mpi: ranks on one host use the ob1 PML" PROPERTIES ENVIRONMENT "${PVR_MPI_ENV}"
                       PASS_REGULAR_EXPRESSION "rank [01] pml ob1\n(.*\n)?rank [01] pml ob1\n" TIMEOUT 60 PROCESSORS 2)
  add_test(NAME "node mpi: ranks on one host keep the PML the user named"
           COMMAND ${PVR_MPIRUN} -np 2 $<TARGET_FILE:pvr_node_mpi_driver> pml)
  set_tests_properties("node mpi: ranks on one host keep the PML the user named"
                       PROPERTIES ENVIRONMENT "${PVR_MPI_ENV};OMPI_MCA_pml=^cm"
                       PASS_REGULAR_EXPRESSION "rank [01] pml \\^cm\n(.*\n)?rank [01] pml \\^cm\n" TIMEOUT 60 PROCESSORS 2)

  # pvr-node --batch's report names every phase and each rank's peak RSS.
  add_test(NAME "node mpi: pvr-node --batch reports every phase and each rank's memory"
           COMMAND ${CMAKE_COMMAND}
                   -DMPIRUN=${MPIEXEC_EXECUTABLE} -DPVR_NODE=$<TARGET_FILE:pvr-node>
                   -DWORK=${PVR_MPI_SCRATCH}/batch-report
                   -P ${CMAKE_CURRENT_SOURCE_DIR}/batch_report_test.cmake)
  set_tests_properties("node mpi: pvr-node --batch reports every phase and each rank's memory"
                       PROPERTIES ENVIRONMENT "${PVR_MPI_ENV}" TIMEOUT 60 PROCESSORS 2)

  # The programs themselves: pvr-node under mpirun against pvr-render, and a
  # bad scene failing on every rank with one message.
  if(TARGET pvr-render)
    add_test(NAME "node mpi: pvr-node --batch equals pvr-render"
             COMMAND ${CMAKE_COMMAND}
                     -DMPIRUN=${MPIEXEC_EXECUTABLE} -DPVR_NODE=$<TARGET_FILE:pvr-node>
                     -DPVR_RENDER=$<TARGET_FILE:pvr-render> -DDRIVER=$<TARGET_FILE:pvr_node_mpi_driver>
                     -DWORK=${PVR_MPI_SCRATCH}/programs
                     -P ${CMAKE_CURRENT_SOURCE_DIR}/pvr_node_test.cmake)
    set_tests_properties("node mpi: pvr-node --batch equals pvr-render"
                         PROPERTIES ENVIRONMENT "${PVR_MPI_ENV}" TIMEOUT 120 PROCESSORS 2)
    add_test(NAME "node mpi: pvr-node --batch renders several volumes as pvr-render on 1 to 4 ranks"
             COMMAND ${CMAKE_COMMAND}
                     -DMPIRUN=${MPIEXEC_EXECUTABLE} -DPVR_NODE=$<TARGET_FILE:pvr-node>
                     -DPVR_RENDER=$<TARGET_FILE:pvr-render> -DDRIVER=$<TARGET_FILE:pvr_node_mpi_driver>
                     -DWORK=${PVR_MPI_SCRATCH}/several-volumes
                     -P ${CMAKE_CURRENT_SOURCE_DIR}/several_volumes_batch_test.cmake)
    set_tests_properties("node mpi: pvr-node --batch renders several volumes as pvr-render on 1 to 4 ranks"
                         PROPERTIES ENVIRONMENT "${PVR_MPI_ENV}" TIMEOUT 180 PROCESSORS 2)
  endif()
endif()
