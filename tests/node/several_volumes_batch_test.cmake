# pvr-node --batch renders a scene of several volumes as pvr-render does,
# on 1 to 4 ranks: two procedural volumes of different spacing, one partly
# inside the other, shaded. The ranks split the union of their domains and
# each holds every volume's nodes around its region (node/scene_bricks.h);
# the tolerance is the one-volume test's, 1e-5 (float rounding of
# compositing regrouped; tests/renderer/raycast_mixed_bricks_test.cpp),
# with early termination off (each brick stops its own part of a ray: with
# it, ranks and one process agree to 1e-4 a brick, which mpi_driver checks).
# The balanced decomposition is refused for such a scene with one message.
file(MAKE_DIRECTORY ${WORK})
file(WRITE ${WORK}/scene.json [=[
{"volumes": [
  {"name": "field", "procedural": "marschner-lobb", "dims": [33, 33, 33], "spacing": [0.07, 0.07, 0.07],
   "transfer_function": {"points": [[0, 0.1, 0.3, 0.9, 0], [0.55, 0.1, 0.3, 0.9, 0], [0.7, 0.3, 0.6, 1, 0.05], [1, 0.8, 0.9, 1, 0.2]]}},
  {"name": "phantom", "procedural": "shepp-logan", "dims": [40, 36, 33],
   "transfer_function": {"points": [[0, 0, 0, 0, 0], [0.15, 0.3, 0.5, 1, 0.02], [0.3, 1, 0.8, 0.3, 0.3], [1, 1, 1, 1, 0.6]]}}],
 "image": {"width": 64, "height": 60},
 "sampling": {"early_termination": 1},
 "shading": {"enabled": true}}
]=])
set(MPI ${MPIRUN} --oversubscribe --bind-to none)

execute_process(COMMAND ${PVR_RENDER} ${WORK}/scene.json -o ${WORK}/reference.exr --threads 1
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "pvr-render failed (${rc}):\n${out}\n${err}")
endif()
foreach(ranks 1 2 3 4)
  execute_process(COMMAND ${MPI} -np ${ranks} ${PVR_NODE} --batch ${WORK}/scene.json -o ${WORK}/ranks-${ranks}.exr
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "pvr-node on ${ranks} ranks failed (${rc}):\n${out}\n${err}")
  endif()
  execute_process(COMMAND ${DRIVER} compare ${WORK}/ranks-${ranks}.exr ${WORK}/reference.exr 1e-5
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out)
  message(STATUS "${ranks} ranks: ${out}")
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "pvr-node on ${ranks} ranks differs from pvr-render")
  endif()
endforeach()

execute_process(COMMAND ${MPI} -np 2 ${PVR_NODE} --batch ${WORK}/scene.json -o ${WORK}/balanced.exr
                        --decomposition balanced
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(rc EQUAL 0 OR NOT err MATCHES "several volumes is split by kd")
  message(FATAL_ERROR "--decomposition balanced should be refused for several volumes; got ${rc}:\n${err}")
endif()
