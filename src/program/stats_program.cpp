// stats_program.cpp — the per-frame statistics as device work (see
// stats_program.h): map kernels write double-float terms, append_reduce_dd
// and append_reduce sum and maximise them in a fixed order, and Copy
// commands gather the results into one small buffer.
#include "program/stats_program.h"

#include <algorithm>
#include <cstring>

#include "contact_params.h"
#include "program/primitives.h"
#include "stats_params.h"

namespace sinew {
namespace {

constexpr std::uint32_t kImpulseFloats = 4 * SINEW_CONTACT_IMPULSE_FLOAT4S;  // per (particle, tool) slot
constexpr std::uint32_t kToolPairs = 12 + SINEW_TOOL_TERMS;  // impulse sums, then mass and inertia

// Word offsets of the item counts in the constants buffer; block k's count at kFirstBlock + k.
enum CountWord : std::uint32_t { kParticles = 0, kFaces = 1, kSlots = 2, kTets = 3, kFirstBlock = 4 };

Result<BufferHandle> make_words(Device& device, std::size_t words, std::string_view label) {
  return device.create_buffer(std::max<std::size_t>(words, 4) * 4, label);
}

// Consecutive ranges of words (scratch of each reduction, results).
struct Layout {
  std::uint32_t next = 0;
  std::uint32_t take(std::uint32_t words) {
    const std::uint32_t at = next;
    next += words;
    return at;
  }
};

// The reductions of a plan, in the order they run.
enum class Reduction { residual_squares, residual_max, kinetic_energy, volume, inverted, tool, end };

// Visits the reductions of a plan in one fixed order, with the scratch and
// result words each one owns; make_stats_plan sizes with it and
// append_stats emits with it, so the two cannot disagree.
template <class Visit>
void for_each_reduction(const StatsPlan& plan, Visit visit) {
  Layout scratch, results;
  if (plan.errors) {
    for (std::size_t k = 0; k < plan.block_sizes.size(); ++k) {
      const std::uint32_t n = plan.block_sizes[k];
      visit(Reduction::residual_squares, k, scratch.take(reduce_dd_scratch_words(n)), results.take(2));
      visit(Reduction::residual_max, k, scratch.take(reduce_scratch_words(n)), results.take(1));
    }
    visit(Reduction::kinetic_energy, 0, scratch.take(reduce_dd_scratch_words(plan.particles)), results.take(2));
    visit(Reduction::volume, 0, scratch.take(reduce_dd_scratch_words(plan.face_capacity)), results.take(2));
    const auto tets = static_cast<std::uint32_t>(plan.tet_list.size());
    if (tets > 0) visit(Reduction::inverted, 0, scratch.take(reduce_scratch_words(tets)), results.take(1));
  }
  for (std::uint32_t k = 0; k < plan.tools * kToolPairs; ++k)
    visit(Reduction::tool, k, scratch.take(reduce_dd_scratch_words(plan.particles)), results.take(2));
  visit(Reduction::end, 0, scratch.next, results.next);
}

double pair(const std::vector<float>& r, std::uint32_t at) { return double(r[at]) + double(r[at + 1]); }

}  // namespace

Result<StatsPlan> make_stats_plan(Device& device, const CompiledScene& scene,
                                  const std::vector<std::array<std::uint32_t, 4>>& faces, bool errors,
                                  std::uint32_t tools, std::uint32_t face_capacity,
                                  std::vector<std::array<std::uint32_t, 4>> tets) {
  StatsPlan plan;
  if (errors) plan.tet_list = std::move(tets);
  for (const auto& t : plan.tet_list) plan.removed_tets += t[0] == t[1] && t[1] == t[2] && t[2] == t[3];
  const auto tet_count = static_cast<std::uint32_t>(plan.tet_list.size());
  plan.errors = errors;
  plan.tools = tools;
  plan.particles = static_cast<std::uint32_t>(scene.positions.size());
  plan.face_count = errors ? static_cast<std::uint32_t>(faces.size()) : 0u;
  plan.face_capacity = errors ? std::max(plan.face_count, face_capacity) : 0u;
  for (const ConstraintBlock& block : scene.blocks) {
    plan.block_sizes.push_back(block.size());
    plan.in_use.push_back(block.in_use());
  }
  if (!errors && tools == 0) return plan;

  std::vector<std::uint32_t> constants{plan.particles, plan.face_count, plan.particles * tools, tet_count};
  constants.insert(constants.end(), plan.block_sizes.begin(), plan.block_sizes.end());
  auto made = make_words(device, constants.size(), "statistics counts");
  if (!made) return made.error();
  plan.constants = *made;
  if (Status s = device.write_buffer(plan.constants, 0, constants.data(), constants.size() * 4); !s) return s.error();
  made = make_words(device, 4 * std::size_t{plan.face_capacity}, "statistics faces");
  if (!made) return made.error();
  plan.faces = *made;
  if (plan.face_count)
    if (Status s = device.write_buffer(plan.faces, 0, faces.data(), faces.size() * sizeof(faces[0])); !s)
      return s.error();
  made = make_words(device, 4 * std::size_t{tet_count}, "statistics tets");
  if (!made) return made.error();
  plan.tets = *made;
  if (tet_count)
    if (Status s = device.write_buffer(plan.tets, 0, plan.tet_list.data(), plan.tet_list.size() * 16); !s)
      return s.error();
  // One terms buffer, reused in turn by each map kernel and its reduction.
  const std::uint32_t terms = std::max(
      {2 * plan.particles, 2 * plan.face_capacity, 2 * SINEW_TOOL_TERMS * plan.particles * tools, tet_count});
  made = make_words(device, terms, "statistics terms");
  if (!made) return made.error();
  plan.terms = *made;

  std::uint32_t scratch_words = 0;
  for_each_reduction(plan, [&](Reduction w, std::size_t k, std::uint32_t scratch, std::uint32_t result) {
    if (w == Reduction::end) {
      scratch_words = scratch;
      plan.result_words = result;
    } else if (w == Reduction::residual_squares) {
      plan.residual_squares.push_back(result);
    } else if (w == Reduction::residual_max) {
      plan.residual_max.push_back(result);
    } else if (w == Reduction::kinetic_energy) {
      plan.kinetic_energy = result;
    } else if (w == Reduction::volume) {
      plan.volume = result;
    } else if (w == Reduction::inverted) {
      plan.inverted = result;
    } else if (w == Reduction::tool && k == 0) {
      plan.tool_first = result;
    }
  });
  made = make_words(device, scratch_words, "statistics scratch");
  if (!made) return made.error();
  plan.scratch = *made;
  made = make_words(device, plan.result_words, "statistics results");
  if (!made) return made.error();
  plan.results = *made;
  plan.read_back.resize(plan.result_words);
  return plan;
}

Status set_stats_faces(Device& device, StatsPlan& plan, const std::vector<std::array<std::uint32_t, 4>>& faces,
                       bool& fitted) {
  fitted = plan.errors && faces.size() <= plan.face_capacity;
  if (!fitted) return {};
  const auto count = static_cast<std::uint32_t>(faces.size());
  if (count > 0)
    if (Status s = device.write_buffer(plan.faces, 0, faces.data(), faces.size() * sizeof(faces[0])); !s) return s;
  if (Status s = device.write_buffer(plan.constants, std::size_t{kFaces} * 4, &count, 4); !s) return s;
  plan.face_count = count;
  return {};
}

Status clear_stats_tets(Device& device, StatsPlan& plan, std::span<const std::uint32_t> removed) {
  for (std::uint32_t t : removed) {
    if (t >= plan.tet_list.size()) continue;  // a plan without errors keeps no tets
    std::array<std::uint32_t, 4>& tet = plan.tet_list[t];
    if (tet[0] == tet[1] && tet[1] == tet[2] && tet[2] == tet[3]) continue;  // removed before
    tet = {tet[1], tet[1], tet[1], tet[1]};
    ++plan.removed_tets;
    if (Status s = device.write_buffer(plan.tets, std::size_t{t} * 16, tet.data(), 16); !s) return s;
  }
  return {};
}

Status release_stats_plan(Device& device, StatsPlan& plan) {
  for (BufferHandle* h : {&plan.constants, &plan.faces, &plan.tets, &plan.terms, &plan.scratch, &plan.results})
    if (h->valid()) {
      if (Status s = device.destroy_buffer(*h); !s) return s;
      *h = {};
    }
  return {};
}

void append_stats(FrameProgram& program, const StatsPlan& plan, const XpbdBuffers& buffers) {
  if (!plan.errors && plan.tools == 0) return;
  const std::uint32_t particles = plan.particles;
  kernels::StatsParams p{};
  for_each_reduction(plan, [&](Reduction w, std::size_t k, std::uint32_t scratch, std::uint32_t result) {
    const DeviceWords at{plan.scratch, scratch};
    std::uint32_t from = 0, words = 2;
    if (w == Reduction::end) return;
    if (w == Reduction::residual_squares || w == Reduction::residual_max) {
      const DeviceCount n{plan.constants, kFirstBlock + static_cast<std::uint32_t>(k), plan.block_sizes[k]};
      const DeviceWords residual{buffers.blocks[k].residual, 0};
      if (w == Reduction::residual_squares) {
        from = append_reduce_dd(program, n, DdItems::squares, residual, 1, at);
      } else {
        from = append_reduce(program, n, ReduceOp::max_f32, residual, 1, at);
        words = 1;
      }
    } else if (w == Reduction::kinetic_energy) {
      p.count = particles;
      program.dispatch(Kernel::stats_kinetic_energy, particles, {buffers.position, buffers.velocity, plan.terms}, p);
      program.barrier();
      from = append_reduce_dd(program, {plan.constants, kParticles, particles}, DdItems::pairs, {plan.terms, 0}, 2, at);
    } else if (w == Reduction::volume) {
      p.count = plan.face_count;
      program.dispatch(Kernel::stats_surface_volume, plan.face_count, {buffers.position, plan.faces, plan.terms}, p);
      program.barrier();
      from = append_reduce_dd(program, {plan.constants, kFaces, plan.face_count}, DdItems::pairs, {plan.terms, 0}, 2, at);
    } else if (w == Reduction::inverted) {
      p.count = static_cast<std::uint32_t>(plan.tet_list.size());
      program.dispatch(Kernel::stats_inverted_tets, p.count, {buffers.position, plan.tets, plan.terms}, p);
      program.barrier();
      from = append_reduce(program, {plan.constants, kTets, p.count}, ReduceOp::sum_u32, {plan.terms, 0}, 1, at);
      words = 1;
    } else {  // tool sums: pair k of tool t
      const auto t = static_cast<std::uint32_t>(k / kToolPairs), j = static_cast<std::uint32_t>(k % kToolPairs);
      if (k == 0) {  // the mass and inertia terms of every (particle, tool) slot, once
        p.count = particles * plan.tools;
        program.dispatch(Kernel::stats_tool_terms, p.count, {buffers.contact_impulses, plan.terms}, p);
        program.barrier();
      }
      const DeviceCount n{plan.constants, kParticles, particles};
      if (j < 12) {  // impulse sum s = j / 3, component j % 3: float (4 s + j % 3) of slot (particle, t)
        const std::uint32_t first = t * kImpulseFloats + 4 * (j / 3) + j % 3;
        from = append_reduce_dd(program, n, DdItems::floats, {buffers.contact_impulses, first},
                                kImpulseFloats * plan.tools, at);
      } else {  // term j - 12 of slot (particle, t)
        const std::uint32_t first = 2 * (t * SINEW_TOOL_TERMS + (j - 12));
        from = append_reduce_dd(program, n, DdItems::pairs, {plan.terms, first}, 2 * SINEW_TOOL_TERMS * plan.tools, at);
      }
    }
    program.copy(plan.scratch, from, plan.results, result, words);
  });
  program.barrier();
  if (plan.result_words > 0) program.read_at_end(plan.results, 0, plan.result_words);
}

Status collect_stats(const Device& device, StatsPlan& plan) {
  if (plan.result_words == 0) return {};
  const std::span<const std::uint32_t> words = device.end_reads();
  if (words.size() < plan.result_words)
    return Error(ErrorCode::internal, "statistics: the frame's last program brought back " +
                                          std::to_string(words.size()) + " words, not its " +
                                          std::to_string(plan.result_words) + " results");
  std::memcpy(plan.read_back.data(), words.data() + (words.size() - plan.result_words), plan.result_words * 4);
  return {};
}

Status read_stats(const StatsPlan& plan, DeviceStats& out) {
  if (plan.result_words == 0) return {};
  const std::vector<float>& r = plan.read_back;
  if (plan.errors) {
    out.residual_sum_squares = 0.0;
    out.residual_max = 0.0;
    out.constraints = 0;
    for (std::size_t k = 0; k < plan.block_sizes.size(); ++k) {
      if (plan.block_sizes[k] == 0) continue;
      out.residual_sum_squares += pair(r, plan.residual_squares[k]);
      out.residual_max = std::max(out.residual_max, double(r[plan.residual_max[k]]));
      out.constraints += plan.in_use[k];
    }
    out.kinetic_energy = pair(r, plan.kinetic_energy);
    out.volume = pair(r, plan.volume) / 6.0;  // the terms are 6 x volume
    out.inverted_tets = 0;
    if (!plan.tet_list.empty()) std::memcpy(&out.inverted_tets, &r[plan.inverted], 4);  // a uint in a float's place
  }
  out.tools.resize(plan.tools);
  for (std::uint32_t t = 0; t < plan.tools; ++t) {
    DeviceStats::Tool& tool = out.tools[t];
    const std::uint32_t first = plan.tool_first + 2 * kToolPairs * t;
    for (int j = 0; j < 12; ++j) tool.sums[j / 3][j % 3] = pair(r, first + 2 * j);
    tool.mass = pair(r, first + 24);
    const int ij[6][2] = {{0, 0}, {0, 1}, {0, 2}, {1, 1}, {1, 2}, {2, 2}};
    for (int k = 0; k < 6; ++k) {
      const double v = pair(r, first + 26 + 2 * k);
      tool.inertia[3 * ij[k][0] + ij[k][1]] = v;
      tool.inertia[3 * ij[k][1] + ij[k][0]] = v;
    }
  }
  return {};
}

}  // namespace sinew
