#include "daemon/core/model/model.h"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace resolver {

Model::Model(ModelSpec spec, int p_r, int p) : spec_(std::move(spec)), p_r_(p_r), p_(p) {
  for (const ModelTerm& t : spec_.terms) {
    std::vector<double> v;
    for (const ParamInfo& info : t.effect->params()) v.push_back(info.neutral);
    values_.push_back(std::move(v));
  }
  std_errors_.assign(spec_.parameter_count(), std::numeric_limits<double>::quiet_NaN());
}

void Model::set(std::string_view name, double value, double std_error) {
  std::size_t k = 0;
  for (std::size_t i = 0; i < spec_.terms.size(); ++i) {
    const ModelTerm& t = spec_.terms[i];
    for (std::size_t j = 0; j < t.params.size(); ++j, ++k) {
      if (t.param_name(j) != name) continue;
      values_[i][static_cast<std::size_t>(t.params[j])] = value;
      if (k < std_errors_.size()) std_errors_[k] = std_error;
      scratch_valid_ = false;
      return;
    }
  }
  throw std::invalid_argument("the model has no fitted parameter '" + std::string(name) + "'");
}

std::vector<ModelParameter> Model::parameters() const {
  std::vector<ModelParameter> out;
  std::size_t k = 0;
  for (std::size_t i = 0; i < spec_.terms.size(); ++i) {
    const ModelTerm& t = spec_.terms[i];
    for (std::size_t j = 0; j < t.params.size(); ++j, ++k) {
      const auto p = static_cast<std::size_t>(t.params[j]);
      out.push_back(ModelParameter{t.param_name(j), values_[i][p],
                                   k < std_errors_.size() ? std_errors_[k] : std::numeric_limits<double>::quiet_NaN(),
                                   std::string(t.effect->params()[p].unit)});
    }
  }
  return out;
}

Design Model::design(std::vector<Nuisance> nuisances) const {
  Design d(spec_, values_, std::move(nuisances));
  d.set_parts(static_cast<int>(frame_shifts_.size()));
  for (std::size_t part = 0; part < frame_shifts_.size(); ++part) d.set_frame_shift(static_cast<int>(part), frame_shifts_[part]);
  return d;
}

void Model::take_values(const Design& design) {
  std::size_t i = 0;
  for (const DesignTerm& t : design.terms()) {
    if (t.candidate) continue;
    if (i < values_.size()) values_[i] = t.values;
    ++i;
  }
  frame_shifts_ = design.frame_shifts();
  scratch_valid_ = false;
}

SignalValues Model::predict(const SignatureRow& row) const { return predict_with_shift(row, 0.0); }

SignalValues Model::predict_in_log_frame(const SignatureRow& row) const {
  return predict_with_shift(row, frame_shift());
}

SignalValues Model::predict_with_shift(const SignatureRow& row, double shift) const {
  if (!scratch_valid_) {
    scratch_ = Design(spec_, values_, {});
    scratch_valid_ = true;
  }
  FitRow r;
  r.sig = row;
  scratch_.set_frame_shift(shift);
  return scratch_.predict(r, basis_);
}

bool Model::has_angle_terms() const {
  for (const ModelTerm& t : spec_.terms) {
    if (!t.effect->current_side()) return true;
  }
  return false;
}

}  // namespace resolver
