// divergence_check.cpp — after every frame, the checks of sinew/divergence.h
// on the statistics the device reduced (no extra read-back), the warning
// through the log callback, and the policy: report, stop, or roll back to
// the last good frame's saved state (also after a frame that failed).
#include <cmath>
#include <sstream>

#include "runtime/simulation_impl.h"
#include "sinew/log.h"

namespace sinew {
namespace {

// The kinetic energy the frame was allowed (sinew/divergence.h): the
// external loads' bound on the mass-weighted speed, times the margin,
// squared; never below the floor.
double energy_bound(const Simulation::Impl& im) {
  const auto& h = im.history;
  const auto& g = im.gravity;
  const double gravity = std::sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
  const double speed = std::sqrt(h.last_energy) + std::sqrt(h.movable_mass / 2.0) * gravity * im.time_step +
                       h.force_speed;
  const double floor_speed =
      im.divergence.floor_speed > 0.0 ? im.divergence.floor_speed : h.extent / im.time_step;
  const double margin = im.divergence.energy_growth * speed;
  return std::max(margin * margin, h.movable_mass / 2.0 * floor_speed * floor_speed);
}

Divergence diagnose(const FrameStats& f, double bound, const DivergenceSettings& settings, std::uint64_t live_tets) {
  if (!std::isfinite(f.kinetic_energy) || !std::isfinite(f.residual_rms) || !std::isfinite(f.max_residual) ||
      !std::isfinite(f.volume_change))
    return Divergence::non_finite;
  if (f.kinetic_energy > bound) return Divergence::energy_growth;
  if (std::abs(f.volume_change) > settings.max_volume_change) return Divergence::volume;
  if (double(f.inverted_tets) > settings.max_inverted_fraction * double(live_tets)) return Divergence::inverted;
  return Divergence::none;
}

}  // namespace

// A checkpoint that cannot be saved (a device error)
// is no reason to fail the frame: the last one stays, and the first
// failure in a row is logged.
void Simulation::Impl::checkpoint() {
  const Status saved = save_state(last_good);
  if (!saved && !checkpoint_failed)
    log_message(LogLevel::warning, saved.error().message() + "; a roll-back goes to frame " +
                                       std::to_string(last_good.frame()) + " until a checkpoint succeeds");
  checkpoint_failed = !saved;
}

Status Simulation::Impl::check_divergence() {
  DivergenceReport& report = stats.divergence;
  report.kind = Divergence::none;
  report.rolled_back = false;
  report.rolled_back_to = 0;
  report.energy_bound = 0.0;
  if (!measure_errors) return {};  // nothing measured, nothing to check (documented)
  report.energy_bound = energy_bound(*this);
  report.kind = diagnose(stats, report.energy_bound, divergence,
                         stats_plan.tet_list.size() - std::uint64_t{stats_plan.removed_tets});
  if (report.kind == Divergence::none) {
    history.last_energy = stats.kinetic_energy;
    if (divergence.on_divergence == OnDivergence::roll_back && stats.frame % divergence.checkpoint_every == 0)
      checkpoint();
    return {};
  }
  ++report.diverged_frames;
  std::ostringstream message;
  message.precision(6);
  message << "frame " << stats.frame << " diverged (" << divergence_name(report.kind) << "): kinetic energy "
          << stats.kinetic_energy << " J (allowed " << report.energy_bound << " J), volume change "
          << stats.volume_change << ", " << stats.inverted_tets << " inverted tets, RMS residual "
          << stats.residual_rms;
  switch (divergence.on_divergence) {
    case OnDivergence::report:
      log_message(LogLevel::warning, message.str());
      // The next frame's bound grows from this one's energy: a report-only
      // run keeps reporting growth, not a finite energy that stopped growing.
      history.last_energy = std::isfinite(stats.kinetic_energy) ? stats.kinetic_energy : history.last_energy;
      return {};
    case OnDivergence::stop:
      log_message(LogLevel::warning, message.str() + "; stopping (on_divergence = stop)");
      return Error(ErrorCode::diverged, "step: " + message.str() +
                                            " (DivergenceSettings::on_divergence = stop; restore_state can go back)");
    case OnDivergence::roll_back: {
      const DivergenceReport diverged = report;
      bool made_again = false;
      if (Status s = restore_state(last_good, "step (rolling back)", &made_again); !s) {
        if (!made_again) return s;
        // Back before a tear of this frame: step() makes the Simulation again.
        pending_roll_back = PendingRollBack{diverged, message.str()};
        return {};
      }
      report_roll_back(diverged, message.str());
      return {};
    }
  }
  return {};
}

void Simulation::Impl::report_roll_back(const DivergenceReport& diverged, const std::string& message) {
  stats.divergence = diverged;
  stats.divergence.rolled_back = true;
  stats.divergence.rolled_back_to = stats.frame;
  log_message(LogLevel::warning, message + "; rolled back to frame " + std::to_string(stats.frame));
}

Status Simulation::Impl::after_failed_frame(const Error& error) {
  if (divergence.on_divergence != OnDivergence::roll_back || last_good.bytes.empty()) return error;
  // The half-done frame's buffers are overwritten by the last good frame's;
  // a device that no longer works fails here too, and both errors are said.
  if (Status s = restore_state(last_good, "step (rolling back after an error)"); !s)
    return Error(error.code(), error.message() + "; rolling back failed too: " + s.error().message());
  stats.divergence.kind = Divergence::none;
  stats.divergence.rolled_back = true;
  stats.divergence.rolled_back_to = stats.frame;
  const std::string message = error.message() + "; rolled back to frame " + std::to_string(stats.frame);
  log_message(LogLevel::warning, message);
  return Error(error.code(), message);
}

Status Simulation::set_divergence_settings(const DivergenceSettings& settings) {
  constexpr const char* call = "set_divergence_settings";
  const auto bad = [&](const char* field, const std::string& rule, double got) {
    std::ostringstream m;
    m << call << ": " << field << " " << rule << " (got " << got << ")";
    return Error(ErrorCode::bad_parameter, m.str());
  };
  if (!(settings.energy_growth > 1.0) || !std::isfinite(settings.energy_growth))
    return bad("energy_growth", "must be a finite number > 1", settings.energy_growth);
  if (!(settings.floor_speed >= 0.0) || !std::isfinite(settings.floor_speed))
    return bad("floor_speed", "must be a finite number >= 0 [m/s]", settings.floor_speed);
  if (!(settings.max_volume_change > 0.0)) return bad("max_volume_change", "must be > 0", settings.max_volume_change);
  if (!(settings.max_inverted_fraction >= 0.0 && settings.max_inverted_fraction <= 1.0))
    return bad("max_inverted_fraction", "must be in [0, 1]", settings.max_inverted_fraction);
  if (settings.checkpoint_every == 0) return bad("checkpoint_every", "must be >= 1", 0.0);
  Impl& im = *impl_;
  if (settings.on_divergence == OnDivergence::roll_back)
    if (Status s = im.save_state(im.last_good); !s) return s;
  im.divergence = settings;
  return {};
}

const DivergenceSettings& Simulation::divergence_settings() const { return impl_->divergence; }

}  // namespace sinew
