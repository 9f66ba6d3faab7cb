#include "drivers/socketcan/can_filter.h"

#include <linux/can.h>

#include <stdexcept>
#include <string>

namespace resolver {

std::vector<CanIdFilter> exact_id_filters(const std::vector<std::uint32_t>& ids) {
  std::vector<CanIdFilter> out;
  out.reserve(ids.size());
  for (const std::uint32_t id : ids) {
    const bool extended = id > CAN_SFF_MASK;
    out.push_back(CanIdFilter{id, extended ? CAN_EFF_MASK : CAN_SFF_MASK, extended});
  }
  return out;
}

KernelCanFilter to_kernel_filter(const CanIdFilter& filter) {
  const std::uint32_t width_mask = filter.extended ? CAN_EFF_MASK : CAN_SFF_MASK;
  if (filter.id > width_mask) {
    throw std::invalid_argument(
        "CAN filter id " + std::to_string(filter.id) + " does not fit in " +
        (filter.extended ? "29 bits" : "11 bits; set extended = true for 29-bit IDs"));
  }
  KernelCanFilter out{};
  out.can_id = filter.id | (filter.extended ? CAN_EFF_FLAG : 0U) | (filter.inverted ? CAN_INV_FILTER : 0U);
  out.can_mask = (filter.mask & width_mask) | CAN_EFF_FLAG;
  return out;
}

}  // namespace resolver
