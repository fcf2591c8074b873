# The Consumer.* tests (tests/CMakeLists.txt): sinew used from outside, as
# docs/using_sinew.md says. Run as
#   cmake -DSTEP=install|find_package|pkg_config -DBUILD_DIR=... -DPREFIX=...
#         -DWORK_DIR=... -DCONFIG=... [-DCXX=... -DGENERATOR=...] -P run_consumer.cmake
#  install:      cmake --install BUILD_DIR --prefix PREFIX (a fresh PREFIX)
#  find_package: configure, build and run this folder's project against PREFIX
#                (no build type, or Debug: unoptimised, to compile fast, and
#                a configuration the installed Release library must serve);
#                with -DPROJECT_DIR=... -DPROGRAM=..., another project built
#                and run the same way (docs/tutorial: Tutorial.FirstScene)
#  pkg_config:   compile and run main.cpp with the flags of
#                `pkg-config --cflags --libs [--static] sinew` (--static
#                for a static libsinew); skipped
#                (SINEW_CONSUMER_SKIPPED, see the test's SKIP_REGULAR_EXPRESSION)
#                where pkg-config is not installed
cmake_minimum_required(VERSION 3.25)

function(run what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE result)
  if(NOT result EQUAL 0)
    message(FATAL_ERROR "consumer: ${what} failed (${result}): ${ARGN}")
  endif()
endfunction()

if(STEP STREQUAL "install")
  file(REMOVE_RECURSE "${PREFIX}")
  run("install" ${CMAKE_COMMAND} --install "${BUILD_DIR}" --prefix "${PREFIX}" --config "${CONFIG}")

elseif(STEP STREQUAL "find_package")
  if(NOT PROJECT_DIR)
    set(PROJECT_DIR "${CMAKE_CURRENT_LIST_DIR}")
    set(PROGRAM consumer)
  endif()
  set(build "${WORK_DIR}/find_package_${PROGRAM}")
  file(REMOVE_RECURSE "${build}")
  run("configure" ${CMAKE_COMMAND} -S "${PROJECT_DIR}" -B "${build}" -G "${GENERATOR}"
      "-DCMAKE_CXX_COMPILER=${CXX}" "-DCMAKE_PREFIX_PATH=${PREFIX}" -DCMAKE_BUILD_TYPE=)
  # The package found must be the one just installed, not another sinew.
  file(STRINGS "${build}/CMakeCache.txt" found REGEX "^sinew_DIR:")
  string(FIND "${found}" "${PREFIX}/" at)
  if(NOT at GREATER 0)
    message(FATAL_ERROR "consumer: found ${found}, not the package under ${PREFIX}")
  endif()
  run("build" ${CMAKE_COMMAND} --build "${build}" --config Debug)
  find_program(program ${PROGRAM} PATHS "${build}" "${build}/Debug" NO_DEFAULT_PATH REQUIRED NO_CACHE)
  run("run" "${program}")

elseif(STEP STREQUAL "pkg_config")
  find_program(pkg_config NAMES pkg-config pkgconf)
  if(NOT pkg_config)
    message("SINEW_CONSUMER_SKIPPED: pkg-config is not installed")
    return()
  endif()
  file(GLOB_RECURSE pc_files "${PREFIX}/*/sinew.pc")
  list(LENGTH pc_files count)
  if(NOT count EQUAL 1)
    message(FATAL_ERROR "consumer: expected one sinew.pc under ${PREFIX}, found: ${pc_files}")
  endif()
  get_filename_component(pc_dir "${pc_files}" DIRECTORY)
  set(ENV{PKG_CONFIG_PATH} "${pc_dir}")
  # --static (Libs.private, Requires.private) for a static libsinew; a
  # shared one carries its dependencies itself.
  set(link "--libs")
  file(GLOB static_library "${PREFIX}/*/libsinew.a" "${PREFIX}/*/*/libsinew.a")
  if(static_library)
    list(APPEND link "--static")
  endif()
  foreach(query "--cflags;${link}" "--modversion" "--variable=libdir")
    execute_process(COMMAND ${pkg_config} ${query} sinew RESULT_VARIABLE result
                    OUTPUT_VARIABLE out OUTPUT_STRIP_TRAILING_WHITESPACE)
    if(NOT result EQUAL 0)
      message(FATAL_ERROR "consumer: pkg-config ${query} sinew failed (${result})")
    endif()
    list(APPEND answers "${out}")
  endforeach()
  list(GET answers 0 flags)
  list(GET answers 1 version)
  list(GET answers 2 libdir)
  string(REPLACE ";" " " query "${link}")
  message(STATUS "pkg-config --cflags ${query} sinew: ${flags}")
  separate_arguments(flags UNIX_COMMAND "${flags}")
  set(build "${WORK_DIR}/pkg_config")
  file(REMOVE_RECURSE "${build}")
  file(MAKE_DIRECTORY "${build}")
  # The run path finds a shared libsinew (harmless for a static one).
  run("compile and link" "${CXX}" -std=c++20 "-DSINEW_CONSUMER_EXPECTED_VERSION=\"${version}\""
      "${CMAKE_CURRENT_LIST_DIR}/main.cpp" ${flags} "-Wl,-rpath,${libdir}" -o "${build}/consumer")
  run("run" "${build}/consumer")

else()
  message(FATAL_ERROR "consumer: unknown STEP '${STEP}'")
endif()
