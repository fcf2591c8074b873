# compare_scene_with_example.cmake — runs a C++ example (with EXAMPLE_ARGS)
# and `sinew run` on its scene file (with RUNNER_ARGS), both on the cpu
# backend, each writing into a folder of WORK, and compares the files
# COMPARE names, "example_file=runner_file", byte for byte. The binary VTU
# files hold every float as stored and the same input gives the same bytes,
# so equal files are bitwise equal positions and fields.
#   cmake -DEXAMPLE=... "-DEXAMPLE_ARGS=--frames;20" -DRUNNER=... -DSCENE=...
#         "-DRUNNER_ARGS=--frames;20" -DWORK=dir "-DCOMPARE=a=b;c=d" -P this
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
execute_process(COMMAND ${EXAMPLE} --backend cpu ${EXAMPLE_ARGS} --out ${WORK}/example
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the example failed (${rc}):\n${out}\n${err}")
endif()
execute_process(COMMAND ${RUNNER} run ${SCENE} --backend cpu ${RUNNER_ARGS} --out ${WORK}/runner
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "sinew run failed (${rc}):\n${out}\n${err}")
endif()
message(STATUS "sinew run:\n${out}")
set(compared 0)
foreach(pair IN LISTS COMPARE)
  if(pair MATCHES "^([^=]+)=(.+)$")
    set(a ${CMAKE_MATCH_1})
    set(b ${CMAKE_MATCH_2})
  else()
    message(FATAL_ERROR "bad COMPARE entry ${pair}")
  endif()
  foreach(f IN ITEMS ${WORK}/example/${a} ${WORK}/runner/${b})
    if(NOT EXISTS ${f})
      message(FATAL_ERROR "${f} was not written")
    endif()
  endforeach()
  # compare_files: binary files (file(READ) would stop at a zero byte).
  execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${WORK}/example/${a} ${WORK}/runner/${b}
                  RESULT_VARIABLE differ)
  if(NOT differ EQUAL 0)
    message(FATAL_ERROR "example/${a} and runner/${b} differ: the scene file does not run as the example")
  endif()
  math(EXPR compared "${compared} + 1")
endforeach()
if(compared EQUAL 0)
  message(FATAL_ERROR "nothing compared")
endif()
message(STATUS "${compared} file pairs bitwise equal")
