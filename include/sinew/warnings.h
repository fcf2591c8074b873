// sinew/warnings.h — what sinew warns about while a scene runs.
//
// Warnings go through the log callback (sinew/log.h) at LogLevel::warning;
// nothing is changed by them: the scene runs as asked. They name a step
// outside what the solver handles well:
//  - when a Simulation is created: a stable Neo-Hookean tet body whose
//    shear-wave Courant number per substep, k = h sqrt(mu / rho) / L (h the
//    substep [s], mu = E / (2 (1 + nu)) [Pa], rho the density [kg/m^3], L
//    the body's 10th-percentile edge length [m]), is above 0.75, where a
//    body at rest blows up (docs/tissue.md; its shear is integrated
//    explicitly by xPBD); the message says how many substeps bring it to 0.2;
//  - after a frame: a diverged frame (sinew/divergence.h: non-finite
//    values, energy growth, inverted elements, volume change);
//  - after a frame: a wall time above WarningSettings::frame_budget_ms
//    (off by default: offline runs are meant to take their time);
//  - after a frame: a count at or above WarningSettings::capacity_fraction
//    of its capacity: every stage counter "X" with a counter
//    "X_capacity" (FrameStats::counter; mesh collision's candidate "pairs",
//    the fluid's "particles"), warned once when it crosses the fraction and
//    again only after it has fallen back below nine tenths of it.
#pragma once

namespace sinew {

/// The per-frame warnings' thresholds (Simulation::set_warning_settings).
struct WarningSettings {
  /// The wall time one step() may take [ms], >= 0; 0: no budget (the
  /// default). A real-time scene sets its frame period (16.7 for 60 Hz).
  /// The first overrun is warned at once; later ones at most once per
  /// repeat_seconds, as a count with the worst frame.
  double frame_budget_ms = 0.0;
  /// Seconds of wall time between two overrun warnings, > 0.
  double repeat_seconds = 5.0;
  /// The fraction of a capacity at which a count is warned, in (0, 1]; 1:
  /// only a count that reached its capacity.
  double capacity_fraction = 0.9;
};

}  // namespace sinew
