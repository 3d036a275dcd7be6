# pvr-node --batch names every phase of its frame, in the order the phases
# follow one another, then their sum and rank 0's wall time, and each
# rank's peak resident memory; the --stats CSV has the same per rank, and
# every rank's peak RSS is at least the voxel bytes it holds (a rank that
# reports less than its brick did not measure itself). Three ranks on a
# procedural volume large enough (64^3 float) that its brick shows in RSS.
cmake_minimum_required(VERSION 3.20)  # policies of this century in -P mode (CMP0012)
file(MAKE_DIRECTORY ${WORK})
file(WRITE ${WORK}/scene.json [=[
{"volume": {"procedural": "shepp-logan", "dims": [64, 64, 64]},
 "transfer_function": {"points": [[0, 0, 0, 0, 0], [0.3, 1, 0.8, 0.3, 0.3], [1, 1, 1, 1, 0.6]]},
 "image": {"width": 48, "height": 40}}
]=])
execute_process(COMMAND ${MPIRUN} --oversubscribe --bind-to none -np 3 ${PVR_NODE} --batch ${WORK}/scene.json
                        -o ${WORK}/report.png --stats ${WORK}/report.csv
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "pvr-node --batch failed (${rc}):\n${out}\n${err}")
endif()
message(STATUS "report:\n${out}")

# The rows, in order, each with a number.
set(from 0)
foreach(row start read prep dist rend comp comm send write sum wall)
  string(REGEX MATCH "\n${row} +[0-9]+\\.[0-9]+" found "${out}")
  string(FIND "${out}" "${found}" at)
  if(found STREQUAL "" OR at LESS from)
    message(FATAL_ERROR "the report has no row '${row}' after the previous one:\n${out}")
  endif()
  set(from ${at})
endforeach()
if(NOT out MATCHES "peak resident memory per rank [^\n]*: 0: [0-9.]+ \\([0-9.]+x\\), 1: [0-9.]+ \\([0-9.]+x\\), 2: [0-9.]+ \\([0-9.]+x\\)\n")
  message(FATAL_ERROR "the report does not give the peak RSS of ranks 0-2:\n${out}")
endif()

# The CSV: a header naming the columns, one row per rank.
file(STRINGS ${WORK}/report.csv lines)
list(LENGTH lines count)
if(NOT count EQUAL 4)
  message(FATAL_ERROR "report.csv should have a header and 3 rows, has ${count} lines")
endif()
list(GET lines 0 header)
string(REPLACE "," ";" header "${header}")
foreach(column brick_bytes start read prep dist write wall peak_rss_bytes)
  list(FIND header ${column} index_${column})
  if(index_${column} EQUAL -1)
    message(FATAL_ERROR "report.csv has no column ${column}: ${header}")
  endif()
endforeach()
# field(RANK COLUMN OUT): rank RANK's value in column COLUMN.
function(field rank column out)
  math(EXPR line "${rank} + 1")
  list(GET lines ${line} row)
  string(REPLACE "," ";" row "${row}")
  list(GET row ${index_${column}} value)
  set(${out} ${value} PARENT_SCOPE)
endfunction()
foreach(rank 0 1 2)
  field(${rank} brick_bytes brick)
  field(${rank} peak_rss_bytes rss)
  if(NOT brick GREATER 0 OR rss LESS brick)
    message(FATAL_ERROR "rank ${rank}: peak RSS ${rss} bytes below its ${brick} voxel bytes")
  endif()
endforeach()
# Rank 0's wall time is its process age when the image was written, taken
# after its start (the age at the frame's start): both from the same clock.
field(0 start start)
field(0 wall wall)
if(NOT start GREATER 0 OR wall LESS start)
  message(FATAL_ERROR "rank 0: start ${start} s and wall ${wall} s out of order")
endif()
