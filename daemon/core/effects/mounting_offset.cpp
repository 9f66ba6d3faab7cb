#include "daemon/core/effects/mounting_offset.h"

#include <array>
#include <cmath>

#include "daemon/core/effects/effect.h"

#include "daemon/core/angles.h"

namespace resolver {

double mounting_offset_resolver_shift(const MountingOffsetParams& m, int p_r, int p) {
  return m["theta_0"] * static_cast<double>(p_r) / static_cast<double>(p);
}

DqCurrents mounting_offset_rotor_currents(const MountingOffsetParams& m, double i_d_cmd, double i_q_cmd) {
  const double c = std::cos(m["theta_0"]);
  const double s = std::sin(m["theta_0"]);
  return {i_d_cmd * c - i_q_cmd * s, i_d_cmd * s + i_q_cmd * c};
}

double mounting_offset_error(const MountingOffsetParams& m, int p_r, int p) {
  return -mounting_offset_resolver_shift(m, p_r, p);
}

double estimate_mounting_offset(double i_d_ref, double i_q_ref, double i_d_cmd, double i_q_cmd) {
  if ((i_d_ref == 0.0 && i_q_ref == 0.0) || (i_d_cmd == 0.0 && i_q_cmd == 0.0)) return 0.0;
  // The rotor-frame vector is the command rotated by +theta_0.
  return wrap_pi(std::atan2(i_q_ref, i_d_ref) - std::atan2(i_q_cmd, i_d_cmd));
}

double compensate_mounting_offset(const MountingOffsetParams& m, double theta_e_drive) {
  return theta_e_drive - m["theta_0"];
}

}  // namespace resolver

// ---- registry unit ------------------------------------------------------------
namespace resolver {
namespace {

class MountingOffsetEffect final : public BasicEffect {
 public:
  MountingOffsetEffect()
      : BasicEffect({"mounting_offset",
                     "drive angle = theta_e + theta_0: eps = -(p_r/p) theta_0; steady i_d = -i_q sin theta_0 in the "
                     "reference frame",
                     "docs/ARCHITECTURE.md section 7; mounting_offset.h",
                     "the resolver is mounted at an angle: a constant position error against the reference, the same "
                     "at every speed and in both directions"},
                    kMountingOffsetParams, EffectStage::kMotion) {}
  [[nodiscard]] bool needs_reference() const override { return true; }
  [[nodiscard]] bool needs_aligned_reference() const override { return true; }
  [[nodiscard]] double resolver_angle_shift(Values v, int p_r, int p) const override {
    return mounting_offset_resolver_shift(MountingOffsetParams(v), p_r, p);
  }
  [[nodiscard]] double drive_frame_offset(Values v) const override { return MountingOffsetParams(v)["theta_0"]; }
  // The windings' errors turn with the seen angle (signature.h's BasisTransform::shift).
  [[nodiscard]] bool shapes_basis() const override { return true; }
  void configure_basis(const SignatureRow& row, Values v, BasisTransform& t) const override {
    t.shift += static_cast<double>(row.p_r) / static_cast<double>(row.p) * MountingOffsetParams(v)["theta_0"];
  }
  // The dq currents against the reference show the offset only as a steady
  // current, which the operating point (the fit's DC i_d, i_q) absorbs: no dq column.
  void signature(const SignatureRow& row, const AngleBasis& /*b*/, Values /*v*/, SignatureColumns& out) const override {
    const double r = static_cast<double>(row.p_r) / static_cast<double>(row.p);
    out.col(MountingOffsetParams::index("theta_0")) = shift_column(-r, r);
  }
};

}  // namespace

const Effect& mounting_offset_effect() {
  static const MountingOffsetEffect effect;
  return effect;
}

}  // namespace resolver
