# Optional dependencies: an option whose dependency is missing turns itself
# off with a message instead of failing the configure.

macro(sinew_optional option_name found_var what)
  if(${option_name} AND NOT ${found_var})
    message(STATUS "sinew: ${option_name} turned OFF: ${what} not found")
    # A plain variable shadows the cached option for this configure only, so
    # installing the dependency later and re-running cmake turns it back on.
    set(${option_name} OFF)
  endif()
endmacro()

if(SINEW_OPENCL)
  find_package(OpenCL QUIET)
  sinew_optional(SINEW_OPENCL OpenCL_FOUND "OpenCL headers/loader (apt-get install ocl-icd-opencl-dev)")
endif()

if(SINEW_VULKAN)
  find_package(Vulkan QUIET COMPONENTS glslc)
  set(_sinew_vulkan_ok FALSE)
  if(Vulkan_FOUND AND Vulkan_GLSLC_EXECUTABLE)
    set(_sinew_vulkan_ok TRUE)
  endif()
  sinew_optional(SINEW_VULKAN _sinew_vulkan_ok "Vulkan loader/headers or glslc (apt-get install libvulkan-dev glslc)")
endif()

if(SINEW_OPENVDB)
  # Debian's FindOpenVDB.cmake hard-fails when a Boost component is missing,
  # so look for the headers and libraries directly.
  find_path(SINEW_OPENVDB_INCLUDE_DIR openvdb/openvdb.h)
  find_path(SINEW_NANOVDB_INCLUDE_DIR nanovdb/NanoVDB.h)
  # The libraries (OpenVDB's and Imath's, libimath-dev) as sinew::openvdb.
  include(${CMAKE_CURRENT_LIST_DIR}/SinewOpenVDBLibraries.cmake)
  set(_sinew_openvdb_ok FALSE)
  if(SINEW_OPENVDB_INCLUDE_DIR AND SINEW_NANOVDB_INCLUDE_DIR AND SINEW_OPENVDB_LIBRARY AND SINEW_IMATH_LIBRARY)
    set(_sinew_openvdb_ok TRUE)
  endif()
  sinew_optional(SINEW_OPENVDB _sinew_openvdb_ok "OpenVDB + NanoVDB (apt-get install libopenvdb-dev libboost-dev)")
endif()

if(SINEW_EMBREE)
  find_package(embree 3 QUIET)
  sinew_optional(SINEW_EMBREE embree_FOUND "Embree 3 (apt-get install libembree-dev)")
endif()

function(sinew_set_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor)
  if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU" AND CMAKE_CXX_COMPILER_VERSION VERSION_LESS 13)
    # GCC 12 reports a false -Wrestrict inside std::string concatenation
    # (GCC bug 105651), which error messages do everywhere.
    target_compile_options(${target} PRIVATE -Wno-restrict)
  endif()
  if(SINEW_WARNINGS_AS_ERRORS)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
endfunction()

# libFuzzer: clang's -fsanitize=fuzzer must compile and link a target.
if(SINEW_FUZZ)
  set(_sinew_fuzz_ok FALSE)
  if(CMAKE_CXX_COMPILER_ID MATCHES "Clang")
    include(CheckCXXSourceCompiles)
    set(CMAKE_REQUIRED_FLAGS "-fsanitize=fuzzer,address,undefined")
    set(CMAKE_REQUIRED_LINK_OPTIONS "-fsanitize=fuzzer,address,undefined")
    check_cxx_source_compiles(
      "#include <cstddef>\n#include <cstdint>\nextern \"C\" int LLVMFuzzerTestOneInput(const std::uint8_t*, std::size_t) { return 0; }"
      SINEW_HAVE_LIBFUZZER)
    unset(CMAKE_REQUIRED_FLAGS)
    unset(CMAKE_REQUIRED_LINK_OPTIONS)
    set(_sinew_fuzz_ok ${SINEW_HAVE_LIBFUZZER})
  endif()
  sinew_optional(SINEW_FUZZ _sinew_fuzz_ok "clang with libFuzzer (-DCMAKE_CXX_COMPILER=clang++)")
endif()
