// level_set_impl.h — what a LevelSet holds (sinew/level_set.h), for sinew's
// own code: the OpenVDB grid, its settings and its NanoVDB copy. Only built
// with OpenVDB (SINEW_OPENVDB).
#pragma once

#include <nanovdb/util/OpenToNanoVDB.h>
#include <openvdb/openvdb.h>

#include "sinew/level_set.h"

namespace sinew {

struct LevelSet::Impl {
  openvdb::FloatGrid::Ptr grid;  ///< the host grid: voxel (i, j, k) at (i, j, k) * voxel [m]
  double voxel = 0.0, exterior = 0.0, interior = 0.0;  ///< [m]
  nanovdb::GridHandle<nanovdb::HostBuffer> nano;       ///< the kernels' copy
};

}  // namespace sinew
