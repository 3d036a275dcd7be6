# pvr-node --batch under mpirun renders what pvr-render renders, for every
# strategy, and its report names the host of the ranks; a scene naming a
# missing volume fails on every rank with one message, naming rank 0's
# host, and a non-zero exit.
file(MAKE_DIRECTORY ${WORK})
file(WRITE ${WORK}/scene.json [=[
{"volume": {"procedural": "shepp-logan", "dims": [40, 36, 33]},
 "transfer_function": {"points": [[0, 0, 0, 0, 0], [0.15, 0.3, 0.5, 1, 0.02], [0.3, 1, 0.8, 0.3, 0.3], [1, 1, 1, 1, 0.6]]},
 "image": {"width": 64, "height": 60},
 "shading": {"enabled": true}}
]=])
set(MPI ${MPIRUN} --oversubscribe --bind-to none)
cmake_host_system_information(RESULT host QUERY HOSTNAME)

execute_process(COMMAND ${PVR_RENDER} ${WORK}/scene.json -o ${WORK}/reference.exr --threads 1
                RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "pvr-render failed: ${rc}")
endif()
foreach(strategy binary-swap direct-send tree radix-k)
  execute_process(COMMAND ${MPI} -np 5 ${PVR_NODE} --batch ${WORK}/scene.json -o ${WORK}/${strategy}.exr
                          --strategy ${strategy} --decomposition balanced --stats ${WORK}/${strategy}.csv
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "pvr-node --strategy ${strategy} failed (${rc}):\n${out}\n${err}")
  endif()
  string(FIND "${out}" "\nhosts: ${host} (ranks 0-4)\n" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "the report does not name ${host} as the host of ranks 0-4:\n${out}")
  endif()
  execute_process(COMMAND ${DRIVER} compare ${WORK}/${strategy}.exr ${WORK}/reference.exr 1e-5
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out)
  message(STATUS "${strategy}: ${out}")
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "pvr-node --strategy ${strategy} differs from pvr-render")
  endif()
endforeach()

file(WRITE ${WORK}/missing.json [=[{"volume": {"file": "no-such-volume.json"}}]=])
execute_process(COMMAND ${MPI} -np 3 ${PVR_NODE} --batch ${WORK}/missing.json -o ${WORK}/missing.exr
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
string(REGEX MATCHALL "pvr-node: rank 0 on ${host}: [^\n]*no-such-volume" lines "${err}")
list(LENGTH lines count)
if(rc EQUAL 0 OR NOT count EQUAL 1)
  message(FATAL_ERROR "a missing volume should fail once on rank 0's stderr, with its host; got ${rc}:\n${err}")
endif()
message(STATUS "missing volume: ${err}")
