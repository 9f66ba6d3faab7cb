// Receive filters for a CAN_RAW socket (CAN_RAW_FILTER).
//
// A frame passes a filter when (received_id & mask) == (id & mask), or, for an
// inverted filter, when it does not. The kernel ORs all filters (ANDs them
// with SocketCanOptions::join_filters); an empty list means "receive everything".
#pragma once

#include <cstdint>
#include <vector>

namespace resolver {

struct CanIdFilter {
  std::uint32_t id;        ///< ID to match (11 or 29 bits, no flag bits)
  std::uint32_t mask;      ///< 1 bits must match; 0x7FF = exact standard ID
  bool extended = false;   ///< match 29-bit frames (true) or 11-bit frames (false)
  bool inverted = false;   ///< pass the frames that do NOT match (CAN_INV_FILTER)
};

/// One filter per ID matching exactly that ID; IDs above 0x7FF are taken as
/// 29-bit ([can] wake_ids).
[[nodiscard]] std::vector<CanIdFilter> exact_id_filters(const std::vector<std::uint32_t>& ids);

/// The kernel's `struct can_filter`, without pulling <linux/can.h> into callers.
struct KernelCanFilter {
  std::uint32_t can_id;
  std::uint32_t can_mask;
};

/// Converts to the kernel form. The EFF flag is always part of the mask, so a
/// standard-ID filter never lets an extended frame with the same low bits
/// through (and vice versa); RTR is left out of the mask, so data and remote
/// frames both pass. Throws std::invalid_argument if `id` does not fit in
/// 11 (standard) or 29 (extended) bits; mask bits beyond the ID width are dropped.
[[nodiscard]] KernelCanFilter to_kernel_filter(const CanIdFilter& filter);

}  // namespace resolver
