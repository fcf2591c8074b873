# OpenVDB's library, and Imath's (OpenVDB's headers convert halves inline
# through Imath, so whatever includes them links it too), as one imported
# target, sinew::openvdb. Debian's FindOpenVDB.cmake hard-fails when a Boost
# component is missing, so the libraries are looked up directly.
#
# Included by the build (cmake/SinewOptions.cmake) and, installed next to it,
# by the package config (sinewConfig.cmake), which links a static libsinew's
# consumers against the same libraries.
find_library(SINEW_OPENVDB_LIBRARY openvdb)
find_library(SINEW_IMATH_LIBRARY NAMES Imath Imath-3_1)
if(SINEW_OPENVDB_LIBRARY AND SINEW_IMATH_LIBRARY AND NOT TARGET sinew::openvdb)
  add_library(sinew::openvdb UNKNOWN IMPORTED)
  set_target_properties(sinew::openvdb PROPERTIES
    IMPORTED_LOCATION "${SINEW_OPENVDB_LIBRARY}"
    INTERFACE_LINK_LIBRARIES "${SINEW_IMATH_LIBRARY}")
endif()
