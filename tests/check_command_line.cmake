# check_command_line.cmake — an example's or benchmark program's command
# line: `PROGRAM --help` exits 0 with a usage text and runs nothing (it
# writes nothing into an empty working folder, quickly); an unknown option
# exits 2 with an error on stderr, and so does a bad --backend where the
# program takes one.
#   cmake -DPROGRAM=path -DWORK=dir -P check_command_line.cmake
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
get_filename_component(name ${PROGRAM} NAME)

function(expect_nothing_written what)
  file(GLOB written ${WORK}/*)
  if(written)
    message(FATAL_ERROR "${name} ${what} wrote ${written}: it ran instead of only parsing its command line")
  endif()
endfunction()

execute_process(COMMAND ${PROGRAM} --help WORKING_DIRECTORY ${WORK} TIMEOUT 30
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${name} --help exited with ${rc} (expected 0):\n${out}\n${err}")
endif()
if(NOT out MATCHES "Usage: ")
  message(FATAL_ERROR "${name} --help printed no \"Usage: \" line:\n${out}\n${err}")
endif()
expect_nothing_written(--help)

execute_process(COMMAND ${PROGRAM} --no-such-option WORKING_DIRECTORY ${WORK} TIMEOUT 30
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 2 OR err STREQUAL "")
  message(FATAL_ERROR "${name} --no-such-option exited with ${rc} (expected 2 and an error on stderr):\n${out}\n${err}")
endif()
expect_nothing_written(--no-such-option)

execute_process(COMMAND ${PROGRAM} --help WORKING_DIRECTORY ${WORK} TIMEOUT 30 OUTPUT_VARIABLE help)
if(help MATCHES "--backend")
  execute_process(COMMAND ${PROGRAM} --backend no_such_backend WORKING_DIRECTORY ${WORK} TIMEOUT 30
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 2 OR NOT err MATCHES "no_such_backend")
    message(FATAL_ERROR "${name} --backend no_such_backend exited with ${rc} (expected 2 and an error naming the "
                        "value):\n${out}\n${err}")
  endif()
  expect_nothing_written("--backend no_such_backend")
endif()
message(STATUS "${name}: --help, an unknown option and a bad value answered as expected")
