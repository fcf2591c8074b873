// sinew/divergence.h — noticing a frame that diverged, and what to do then.
//
// After every frame the Simulation checks the statistics the device reduced
// at the frame's end (FrameStats: kinetic energy, residuals, volume change;
// a few words, no extra read-back) for three signs that the solve blew up:
// a non-finite value, kinetic energy that grew beyond what the frame's
// external loads can supply, tet bodies whose total volume collapsed or
// doubled, and many tets turned inside out. A diverged frame is reported in FrameStats::divergence
// and as a warning through the log callback (sinew/log.h); the policy
// (DivergenceSettings::on_divergence) then either leaves it at that, stops
// with an ErrorCode::diverged error, or rolls the scene back to the last
// good frame (Simulation::save_state).
//
// The checks read FrameStats' errors, so they need SolverSettings::
// measure_errors (the default); without it no frame is ever found diverged.
#pragma once

#include <cstdint>

namespace sinew {

/// What made a frame count as diverged (the first sign found, in this order).
enum class Divergence : std::uint8_t {
  none,           ///< the frame passed every check
  non_finite,     ///< kinetic energy, a residual or the volume change is NaN or infinite
  energy_growth,  ///< kinetic energy grew beyond DivergenceSettings' bound (FrameStats::divergence.energy_bound)
  volume,         ///< the tet bodies' total volume changed by more than max_volume_change
  inverted,       ///< more than max_inverted_fraction of the live tets are inverted (FrameStats::inverted_tets)
};

/// The name of a Divergence: "none", "non_finite", "energy_growth", "volume", "inverted".
constexpr const char* divergence_name(Divergence d) {
  switch (d) {
    case Divergence::none: return "none";
    case Divergence::non_finite: return "non_finite";
    case Divergence::energy_growth: return "energy_growth";
    case Divergence::volume: return "volume";
    case Divergence::inverted: return "inverted";
  }
  return "unknown";
}

/// What step() does about a diverged frame. Each also logs a warning.
enum class OnDivergence : std::uint8_t {
  report,     ///< step() succeeds; FrameStats::divergence says what happened
  stop,       ///< step() returns ErrorCode::diverged; the diverged state stays (restore_state can undo it)
  roll_back,  ///< the scene goes back to the last good frame (FrameStats::divergence.rolled_back_to) and
              ///< step() succeeds: the next step() runs that frame's successor again. A frame that fails
              ///< (a device error) rolls back too, and step() returns its error, saying so
};

/// The divergence checks and their policy (Simulation::set_divergence_settings).
///
/// The energy check. The external loads of one frame of length dt (gravity
/// g, the particle forces f of set_particle_forces) can raise the particles'
/// mass-weighted speed sqrt(2 K) by at most sqrt(M) |g| dt + sqrt(sum dt^2
/// |f|^2 / m) (M: the movable mass), so a frame that starts with kinetic
/// energy K0 ends, by those loads alone, with at most
///   K_ext = (sqrt(K0) + sqrt(M/2) |g| dt + sqrt(sum dt^2 |f|^2 / (2 m)))^2  [J].
/// The tissue's own elastic energy, tools and moving colliders add to it, so
/// the bound allows a margin: a frame diverged when its kinetic energy
/// exceeds energy_growth^2 K_ext and also exceeds the floor M/2 v_floor^2,
/// v_floor = floor_speed (0: the starting scene's bounding-box diagonal per
/// frame, i.e. every particle crossing the whole scene each frame).
struct DivergenceSettings {
  OnDivergence on_divergence = OnDivergence::report;
  /// The margin on the mass-weighted speed the external loads allow (> 1; energy: its square).
  double energy_growth = 10.0;
  /// The RMS speed below which no energy growth counts as divergence [m/s], >= 0 (0: automatic, above).
  double floor_speed = 0.0;
  /// The largest |FrameStats::volume_change| of a healthy frame, > 0 (1: the tet bodies' total volume
  /// reached zero or doubled).
  double max_volume_change = 1.0;
  /// The largest fraction of the live tets that may be inverted in a healthy frame, in [0, 1] (stable
  /// Neo-Hookean and corotational materials recover from a few inverted tets; an exploding body inverts
  /// many).
  double max_inverted_fraction = 0.25;
  /// roll_back: save the state of every n-th good frame (>= 1) to roll back to; each save reads the
  /// particles' positions, velocities and multipliers back from the device (Simulation::save_state).
  std::uint32_t checkpoint_every = 1;
};

/// The checks' verdict on the last frame (FrameStats::divergence).
struct DivergenceReport {
  Divergence kind = Divergence::none;
  double energy_bound = 0.0;  ///< the kinetic energy the frame was allowed [J] (0 with measure_errors off)
  /// roll_back: the frame rolled back to (FrameStats::frame is then this frame); 0 otherwise.
  std::uint64_t rolled_back_to = 0;
  bool rolled_back = false;  ///< the scene was rolled back after this frame
  std::uint64_t diverged_frames = 0;  ///< frames found diverged since the Simulation was created
};

}  // namespace sinew
