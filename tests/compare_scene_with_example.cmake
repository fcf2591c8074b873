# compare_scene_with_example.cmake — runs a C++ example and `sinew run` on
# its scene file for FRAMES frames on the cpu backend, each writing into a
# folder of WORK, and compares the files COMPARE names (a list of
# "example_file=runner_file") byte for byte: the VTU files hold every
# vertex's float position, so equal files are bitwise equal positions.
#   cmake -DEXAMPLE=... -DRUNNER=... -DSCENE=... -DFRAMES=N -DWORK=dir -DCOMPARE=a=b;c=d -P this
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
execute_process(COMMAND ${EXAMPLE} --backend cpu --frames ${FRAMES} --out ${WORK}/example
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the example failed (${rc}):\n${out}\n${err}")
endif()
execute_process(COMMAND ${RUNNER} run ${SCENE} --backend cpu --frames ${FRAMES} --every 10 --out ${WORK}/runner
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "sinew run failed (${rc}):\n${out}\n${err}")
endif()
message(STATUS "sinew run:\n${out}")
set(compared 0)
foreach(pair IN LISTS COMPARE)
  string(REPLACE "=" ";" files ${pair})
  list(GET files 0 a)
  list(GET files 1 b)
  foreach(f IN ITEMS ${WORK}/example/${a} ${WORK}/runner/${b})
    if(NOT EXISTS ${f})
      message(FATAL_ERROR "${f} was not written")
    endif()
  endforeach()
  execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${WORK}/example/${a} ${WORK}/runner/${b} RESULT_VARIABLE differ)
  if(NOT differ EQUAL 0)
    message(FATAL_ERROR "example/${a} and runner/${b} differ: the scene file does not run as the example")
  endif()
  math(EXPR compared "${compared} + 1")
endforeach()
if(compared EQUAL 0)
  message(FATAL_ERROR "nothing compared")
endif()
message(STATUS "${compared} file pairs bitwise equal")
