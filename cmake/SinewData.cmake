# Test data for tests, examples and benchmarks: the repository's data/ made
# whole in the build folder, so nothing is generated in the source tree.
# Plain files are copied; the large text tet meshes, stored as *.tar.xz, are
# unpacked beside them by CMake's own libarchive (no xz tool needed).
# Re-configuring is quick: file(COPY) skips files whose timestamps match, and
# an archive is unpacked again only when it is newer than its stamp.
#   sinew_prepare_data(SOURCE_DIR DATA_DIR)
function(sinew_prepare_data source_dir data_dir)
  file(GLOB_RECURSE files CONFIGURE_DEPENDS RELATIVE ${source_dir} ${source_dir}/*)
  list(TRANSFORM files PREPEND ${source_dir}/ OUTPUT_VARIABLE paths)
  set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${paths})

  file(COPY ${source_dir}/ DESTINATION ${data_dir} PATTERN "*.tar.xz" EXCLUDE)

  set(stamps ${CMAKE_CURRENT_BINARY_DIR}/CMakeFiles/sinew_data)
  list(FILTER files INCLUDE REGEX "\\.tar\\.xz$")
  foreach(archive IN LISTS files)
    set(stamp ${stamps}/${archive}.stamp)
    if(${source_dir}/${archive} IS_NEWER_THAN ${stamp})
      get_filename_component(dir ${archive} DIRECTORY)
      message(STATUS "sinew: unpacking data/${archive}")
      file(ARCHIVE_EXTRACT INPUT ${source_dir}/${archive} DESTINATION ${data_dir}/${dir} TOUCH)
      get_filename_component(stamp_dir ${stamp} DIRECTORY)
      file(MAKE_DIRECTORY ${stamp_dir})
      file(TOUCH ${stamp})
    endif()
  endforeach()
endfunction()
