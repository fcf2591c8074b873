// suture_exemption.h — which contacts a suture exempts (issue 13, part 4):
// a thread runs through the tissue at its punctures, so neither the
// frame's mesh contacts nor continuous collision may push it out there.
// Sutures (sutures.h) marks, per particle in device order, the threads of
// needles that hold punctures (kThread) and the tissue around each hole:
// the vertices of every surface triangle sharing a vertex with a punctured
// one (kHole). A contact or CCD pair is exempt when it joins a thread
// particle and a hole particle.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

namespace sinew {

inline constexpr std::uint8_t kSutureThread = 1, kSutureHole = 2;

/// Whether `particles` (device order) join a thread and a hole. [in] mask:
/// per particle (or empty: nothing is exempt).
inline bool suture_exempt(const std::vector<std::uint8_t>* mask, std::span<const std::uint32_t> particles) {
  if (!mask || mask->empty()) return false;
  std::uint8_t seen = 0;
  for (std::uint32_t p : particles) seen |= (*mask)[p];
  return (seen & kSutureThread) && (seen & kSutureHole);
}

}  // namespace sinew
