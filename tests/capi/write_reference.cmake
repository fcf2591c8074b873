# The C API tests' fixture (tests/CMakeLists.txt, capi.reference_*): the
# positions `sinew run` ends with, as the C API's test compares them.
#   cmake -DRUNNER=... -DSCENE=... -DBACKEND=... -DFRAMES=... -DOUTPUT=... -P write_reference.cmake
# A backend that `sinew info` reports unavailable here (not built in, or no
# device) prints SINEW_CAPI_SKIPPED (the test's SKIP_REGULAR_EXPRESSION):
# the C test then skips itself on the same backend.
cmake_minimum_required(VERSION 3.25)
execute_process(COMMAND ${RUNNER} info OUTPUT_VARIABLE info RESULT_VARIABLE result)
if(NOT result EQUAL 0)
  message(FATAL_ERROR "sinew info failed (${result})")
endif()
string(REGEX MATCH "backends built in: [^\n]*" built "${info}")
if(NOT built MATCHES " ${BACKEND}( |$)" OR info MATCHES "(^|\n)${BACKEND}: unavailable")
  message("SINEW_CAPI_SKIPPED: the ${BACKEND} backend is not available here")
  return()
endif()
file(REMOVE "${OUTPUT}")
execute_process(COMMAND ${RUNNER} run ${SCENE} --backend ${BACKEND} --frames ${FRAMES} --quiet --positions ${OUTPUT}
                RESULT_VARIABLE result)
if(NOT result EQUAL 0)
  message(FATAL_ERROR "sinew run ${SCENE} --backend ${BACKEND} failed (${result})")
endif()
