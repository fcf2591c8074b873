# `cmake --install`: libsinew (static, or shared with BUILD_SHARED_LIBS), its
# public headers with the generated sinew/version.h, a CMake package
# (find_package(sinew 0.1 CONFIG) -> sinew::sinew) and a pkg-config file
# (sinew.pc). How to use them: docs/using_sinew.md.
#
# No kernel files are installed: the GPU kernels are in the library itself
# (OpenCL C as strings, SPIR-V as words, both generated into the build folder
# and compiled in), so nothing is looked up at run time.
include(CMakePackageConfigHelpers)
set(SINEW_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/sinew)

install(TARGETS sinew EXPORT sinewTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
# Public headers only: include/sinew/ includes nothing from src/ or kernels/.
install(DIRECTORY ${PROJECT_SOURCE_DIR}/include/sinew DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
        FILES_MATCHING PATTERN "*.h")
install(FILES ${PROJECT_BINARY_DIR}/include/sinew/version.h DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/sinew)

# ------------------------------------------------------------- CMake package
install(EXPORT sinewTargets NAMESPACE sinew:: DESTINATION ${SINEW_INSTALL_CMAKEDIR})
# What the package config finds for a static libsinew's users, exactly as
# this build was configured (an optional dependency that was not found is off).
if(BUILD_SHARED_LIBS)
  set(SINEW_PACKAGE_SHARED ON)
else()
  set(SINEW_PACKAGE_SHARED OFF)
endif()
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/sinewConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/package/sinewConfig.cmake
                              INSTALL_DESTINATION ${SINEW_INSTALL_CMAKEDIR})
# 0.x: a minor version may change the API and the ABI (semantic versioning
# promises nothing before 1.0), so 0.1 accepts 0.1.z only, not 0.2. From
# 1.0 on this becomes SameMajorVersion.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/package/sinewConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/package/sinewConfig.cmake
              ${PROJECT_BINARY_DIR}/package/sinewConfigVersion.cmake
              ${PROJECT_SOURCE_DIR}/cmake/SinewOpenVDBLibraries.cmake
        DESTINATION ${SINEW_INSTALL_CMAKEDIR})

# ------------------------------------------------------------- pkg-config
# sinew.pc finds its prefix from its own folder (${pcfiledir}), so the
# installed tree may be moved or installed with `cmake --install --prefix`.
# A static libsinew's dependencies: Requires.private for those pkg-config
# knows (tbb, OpenCL, vulkan on Debian), the library files otherwise
# (Embree, OpenVDB, Imath) in Libs.private.
find_package(PkgConfig QUIET)
set(SINEW_PC_REQUIRES_PRIVATE "")
set(SINEW_PC_LIBS_PRIVATE "")

# Appends to SINEW_PC_LIBS_PRIVATE the link flags of ITEM: a library file
# (as -L<dir> -l<name>) or an imported target (its file, then its interface).
function(sinew_pc_link_flags item)
  if(TARGET ${item})
    get_target_property(type ${item} TYPE)
    if(NOT type STREQUAL "INTERFACE_LIBRARY")
      get_target_property(location ${item} LOCATION)
      sinew_pc_link_flags(${location})
    endif()
    get_target_property(interface ${item} INTERFACE_LINK_LIBRARIES)
    foreach(dependency IN LISTS interface)
      if(dependency AND NOT dependency MATCHES "^\\$<")
        sinew_pc_link_flags(${dependency})
      endif()
    endforeach()
  elseif(item MATCHES "^-")
    list(APPEND SINEW_PC_LIBS_PRIVATE ${item})
  elseif(IS_ABSOLUTE "${item}")
    get_filename_component(dir "${item}" DIRECTORY)
    get_filename_component(file "${item}" NAME)
    if(file MATCHES "^lib(.+)\\.(so|a)(\\.[0-9.]+)?$")
      list(APPEND SINEW_PC_LIBS_PRIVATE "-L${dir}" "-l${CMAKE_MATCH_1}")
    else()
      list(APPEND SINEW_PC_LIBS_PRIVATE "${item}")
    endif()
  else()
    list(APPEND SINEW_PC_LIBS_PRIVATE "-l${item}")
  endif()
  list(REMOVE_DUPLICATES SINEW_PC_LIBS_PRIVATE)
  set(SINEW_PC_LIBS_PRIVATE ${SINEW_PC_LIBS_PRIVATE} PARENT_SCOPE)
endfunction()

# TARGET's library in sinew.pc: as pkg-config MODULE when pkg-config has it.
function(sinew_pc_dependency target module)
  if(PKG_CONFIG_FOUND AND module)
    pkg_check_modules(SINEW_PC_${module} QUIET ${module})
    if(SINEW_PC_${module}_FOUND)
      set(SINEW_PC_REQUIRES_PRIVATE ${SINEW_PC_REQUIRES_PRIVATE} ${module} PARENT_SCOPE)
      return()
    endif()
  endif()
  sinew_pc_link_flags(${target})
  set(SINEW_PC_LIBS_PRIVATE ${SINEW_PC_LIBS_PRIVATE} PARENT_SCOPE)
endfunction()

sinew_pc_dependency(TBB::tbb tbb)
sinew_pc_dependency(ZLIB::ZLIB zlib)
if(SINEW_OPENCL)
  sinew_pc_dependency(OpenCL::OpenCL OpenCL)
endif()
if(SINEW_VULKAN)
  sinew_pc_dependency(Vulkan::Vulkan vulkan)
endif()
if(SINEW_EMBREE)
  sinew_pc_dependency(embree "")
endif()
if(SINEW_OPENVDB)
  sinew_pc_dependency(sinew::openvdb "")
endif()
# dlopen for the haptic device plug-ins (-ldl; nothing where libc has it).
foreach(library IN LISTS CMAKE_DL_LIBS)
  sinew_pc_link_flags(${library})
endforeach()
list(JOIN SINEW_PC_REQUIRES_PRIVATE ", " SINEW_PC_REQUIRES_PRIVATE)
list(JOIN SINEW_PC_LIBS_PRIVATE " " SINEW_PC_LIBS_PRIVATE)

if(IS_ABSOLUTE "${CMAKE_INSTALL_LIBDIR}")
  set(SINEW_PC_PREFIX "${CMAKE_INSTALL_PREFIX}")
  set(SINEW_PC_LIBDIR "${CMAKE_INSTALL_LIBDIR}")
else()
  file(RELATIVE_PATH relative "/prefix/${CMAKE_INSTALL_LIBDIR}/pkgconfig" "/prefix")
  string(REGEX REPLACE "/$" "" relative "${relative}")
  set(SINEW_PC_PREFIX "\${pcfiledir}/${relative}")
  set(SINEW_PC_LIBDIR "\${prefix}/${CMAKE_INSTALL_LIBDIR}")
endif()
if(IS_ABSOLUTE "${CMAKE_INSTALL_INCLUDEDIR}")
  set(SINEW_PC_INCLUDEDIR "${CMAKE_INSTALL_INCLUDEDIR}")
else()
  set(SINEW_PC_INCLUDEDIR "\${prefix}/${CMAKE_INSTALL_INCLUDEDIR}")
endif()
# Threads is public (the headers use std::thread): -pthread where the
# compiler needs it (nothing with glibc >= 2.34).
string(STRIP "-L\${libdir} -lsinew ${CMAKE_THREAD_LIBS_INIT}" SINEW_PC_LIBS)
configure_file(${PROJECT_SOURCE_DIR}/cmake/sinew.pc.in ${PROJECT_BINARY_DIR}/package/sinew.pc @ONLY)
install(FILES ${PROJECT_BINARY_DIR}/package/sinew.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
