// scene_compiler.h — turns a SceneDesc into flat arrays ready for a device:
// float4 particles (xyz + inverse mass), and per constraint type a
// structure-of-arrays sorted by colour, with each colour's range.
#pragma once

#include <cstdint>
#include <vector>

#include "cpu/cpu_math.h"
#include "sinew/scene.h"
#include "sinew/simulation.h"

namespace sinew {

/// Constraints solved by one kernel (arity particles each), sorted by
/// colour: colour k holds constraints [color_offsets[k], color_offsets[k+1]).
/// The solve kernels' bindings are described in kernels/shared/xpbd_params.h.
/// Scene-wide buffers a solve kernel may bind after its five standard ones.
enum class SceneBuffer { previous_position };

struct ConstraintBlock {
  Kernel kernel = Kernel::count_;
  std::uint32_t arity = 0;
  std::uint32_t data_stride = 2;          ///< floats of data per constraint
  std::uint32_t lambda_stride = 1;        ///< lambdas per constraint
  std::vector<SceneBuffer> extra_bindings;
  std::vector<std::uint32_t> particles;   ///< arity per constraint
  std::vector<float> data;                ///< data_stride per constraint, e.g. (rest value, compliance alpha)
  std::vector<std::uint32_t> color_offsets{0};
  [[nodiscard]] std::uint32_t size() const { return arity ? static_cast<std::uint32_t>(particles.size() / arity) : 0; }
  [[nodiscard]] std::uint32_t colors() const { return static_cast<std::uint32_t>(color_offsets.size() - 1); }
};

/// The constraints of one kind before colouring.
struct RawConstraints {
  Kernel kernel;
  std::uint32_t arity;
  std::uint32_t data_stride = 2;
  std::uint32_t lambda_stride = 1;
  std::vector<SceneBuffer> extra_bindings = {};
  std::vector<std::uint32_t> particles = {};
  std::vector<float> data = {};
};

struct CompiledScene {
  std::vector<kernels::float4> positions;  ///< xyz [m], w = inverse mass [1/kg]
  /// Solved in this order in every iteration; empty blocks are left out.
  std::vector<ConstraintBlock> blocks;
  std::vector<std::uint32_t> tet_body_first_particle;
  std::vector<std::uint32_t> line_body_first_particle;
};

/// Checks (check_scene) and compiles a scene. Errors name the parameter.
Result<CompiledScene> compile_scene(const SceneDesc& scene);

}  // namespace sinew
