#include "daemon/core/estimation/estimator_models.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "daemon/core/effects/amplitude_imbalance.h"
#include "daemon/core/effects/harmonics.h"
#include "daemon/core/effects/mounting_offset.h"
#include "daemon/core/effects/offsets.h"
#include "daemon/core/effects/quadrature.h"
#include "daemon/core/effects/registry.h"

namespace resolver {

namespace {

/// Collects (effect, parameter, value, standard error) and builds the Model with
/// exactly those parameters fitted, in the order the effects were first named.
class ModelBuilder {
 public:
  ModelBuilder& add(const Effect& effect, std::string_view param, const Estimate& e) {
    return add(effect, param, e.value, e.std_error);
  }
  ModelBuilder& add(const Effect& effect, std::string_view param, double value, double std_error) {
    const int i = find_param(effect, param);
    if (i < 0) throw std::logic_error(std::string(effect.name()) + " has no parameter " + std::string(param));
    spec_.add(ModelTerm{&effect, {i}});
    values_.push_back({&effect, i, value, std_error});
    return *this;
  }
  [[nodiscard]] Model build(int p_r, int p) const {
    Model m(spec_, p_r, p);
    for (const Value& v : values_) {
      const ModelTerm term{v.effect, {v.param}};
      m.set(term.param_name(0), v.value, v.std_error);
    }
    return m;
  }

 private:
  struct Value {
    const Effect* effect;
    int param;
    double value, std_error;
  };
  ModelSpec spec_;
  std::vector<Value> values_;
};

/// alpha, beta, o_s, o_c: the envelope effects both sin/cos-based fits name.
template <typename Fit>
void add_envelope(ModelBuilder& b, const Fit& f) {
  b.add(amplitude_imbalance_effect(), "alpha", f.alpha)
      .add(quadrature_effect(), "beta", f.beta)
      .add(offsets_effect(), "o_s", f.o_s)
      .add(offsets_effect(), "o_c", f.o_c);
}

double finite_or_zero(double x) { return std::isfinite(x) ? x : 0.0; }

}  // namespace

Model hwang_model(double alpha, double alpha_std_error, int p_r, int p) {
  return ModelBuilder().add(amplitude_imbalance_effect(), "alpha", alpha, alpha_std_error).build(p_r, p);
}

Model sincos_model(const SinCosFit& fit, int p_r, int p) {
  ModelBuilder b;
  add_envelope(b, fit);
  for (std::size_t i = 0; i < fit.k.size() && i < fit.harmonic_orders.size(); ++i) {
    b.add(harmonics_effect(), "k" + std::to_string(fit.harmonic_orders[i]), fit.k[i]);
  }
  return b.build(p_r, p);
}

Model fourier_model(const AngleErrorFit& fit, int p_r, int p) {
  ModelBuilder b;
  add_envelope(b, fit);
  const int top = std::min({fit.max_order, kFourierModelMaxOrder, static_cast<int>(fit.a.size()) - 1,
                            static_cast<int>(fit.b.size()) - 1});
  for (int m = 3; m <= top; ++m) {
    const Estimate& a = fit.a[static_cast<std::size_t>(m)];
    const Estimate& s = fit.b[static_cast<std::size_t>(m)];
    b.add(harmonics_effect(), "k" + std::to_string(m + 1), -a.value, a.std_error);
    b.add(harmonics_effect(), "k" + std::to_string(m + 1) + "_q", -s.value, s.std_error);
  }
  // The series' constant: a_0 plus the -beta/2 the quadrature term brings along.
  const double constant = finite_or_zero(fit.a0.value) + 0.5 * finite_or_zero(fit.beta.value);
  const double ratio = static_cast<double>(p) / static_cast<double>(p_r);
  b.add(mounting_offset_effect(), "theta_0", -ratio * constant, ratio * fit.a0.std_error);
  return b.build(p_r, p);
}

}  // namespace resolver
