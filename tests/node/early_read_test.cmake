# pvr-node --batch with PVR_EARLY_READ=1 reads each rank's brick while MPI
# starts (node/early_read.h) when it reads its own box of a raw file (slabs
# and kd), and renders the very frame it renders reading after MPI_Init
# (PVR_EARLY_READ=0, as unset) and what
# pvr-render renders; a balanced decomposition (it reads twice) reads as
# always. The --stats CSV's read_early column says which.
cmake_minimum_required(VERSION 3.20)
file(MAKE_DIRECTORY ${WORK})
file(WRITE ${WORK}/scene.json "{\"volume\": {\"file\": \"${DATA}/mri_head_volpack/mri_head_volpack.json\"},
 \"transfer_function\": {\"points\": [[0, 0, 0, 0, 0], [40, 0, 0, 0, 0], [90, 0.9, 0.7, 0.5, 0.05], [255, 1, 1, 1, 0.8]]},
 \"image\": {\"width\": 64, \"height\": 56}, \"shading\": {\"enabled\": true}}")
set(MPI ${MPIRUN} --oversubscribe --bind-to none)

# batch(NAME DECOMPOSITION EARLY): runs 3 ranks with PVR_EARLY_READ=EARLY and
# sets NAME_flags to the ranks' read_early column.
function(batch name decomposition early)
  execute_process(COMMAND ${CMAKE_COMMAND} -E env PVR_EARLY_READ=${early}
                          ${MPI} -np 3 ${PVR_NODE} --batch ${WORK}/scene.json -o ${WORK}/${name}.exr
                          --decomposition ${decomposition} --stats ${WORK}/${name}.csv
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "pvr-node --decomposition ${decomposition} (PVR_EARLY_READ=${early}) failed (${rc}):\n${out}\n${err}")
  endif()
  file(STRINGS ${WORK}/${name}.csv lines)
  list(GET lines 0 header)
  string(REPLACE "," ";" header "${header}")
  list(FIND header read_early column)
  if(column EQUAL -1)
    message(FATAL_ERROR "${name}.csv has no column read_early: ${header}")
  endif()
  set(flags "")
  foreach(rank 1 2 3)
    list(GET lines ${rank} row)
    string(REPLACE "," ";" row "${row}")
    list(GET row ${column} flag)
    string(APPEND flags "${flag}")
  endforeach()
  set(${name}_flags ${flags} PARENT_SCOPE)
  message(STATUS "${name}: read_early ${flags}")
endfunction()

# same(A B TOLERANCE): the two images agree within TOLERANCE.
function(same a b tolerance)
  execute_process(COMMAND ${DRIVER} compare ${WORK}/${a}.exr ${WORK}/${b}.exr ${tolerance}
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out)
  message(STATUS "${a} against ${b}: ${out}")
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${a} differs from ${b} beyond ${tolerance}")
  endif()
endfunction()

execute_process(COMMAND ${PVR_RENDER} ${WORK}/scene.json -o ${WORK}/reference.exr --threads 1 RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "pvr-render failed: ${rc}")
endif()
foreach(decomposition slabs kd)
  batch(${decomposition}_early ${decomposition} 1)
  batch(${decomposition}_after ${decomposition} 0)
  if(NOT ${decomposition}_early_flags STREQUAL "111" OR NOT ${decomposition}_after_flags STREQUAL "000")
    message(FATAL_ERROR "${decomposition}: every rank should read early (111) with PVR_EARLY_READ=1 and none with 0 (000); "
                        "got ${${decomposition}_early_flags} and ${${decomposition}_after_flags}")
  endif()
  same(${decomposition}_early ${decomposition}_after 0)
  same(${decomposition}_early reference 1e-5)
endforeach()
batch(balanced balanced 1)
if(NOT balanced_flags STREQUAL "000")
  message(FATAL_ERROR "a balanced decomposition reads twice and should read nothing early; got ${balanced_flags}")
endif()
same(balanced reference 1e-5)
