// Passes over many rows on several threads, with an answer that does not depend on
// how many: the rows are cut into blocks of a fixed size, each block summed alone
// (on whichever thread is free), and the blocks' sums added in block order. A pass is
// then the same to the last bit on one thread or eight (on one CPU: the maths library
// picks its sin and cos by the processor, so another machine may differ in the last
// bits whatever the threads).
//
// The offline tools set the thread count once (resolver-model --threads); the default
// is one, so the daemon's live windows (a few thousand rows, one block) run on its fit
// thread as before.
#pragma once

#include <cstddef>
#include <functional>

namespace resolver {

/// Rows per block: a block of a 10 kHz log is 3.3 s, long against the cost of starting a
/// thread and of adding the block's sums (~100 us for 130 columns), short against a log.
inline constexpr std::size_t kRowBlock = 32768;

/// Threads a pass over rows may use from now on (at least 1).
void set_pass_threads(int threads);
[[nodiscard]] int pass_threads();

/// Workers over_row_blocks uses for `rows` rows: pass_threads(), but no more than blocks.
[[nodiscard]] int row_block_workers(std::size_t rows);

/// Calls work(worker, from, to) for every block [from, to) of kRowBlock rows of [0, rows),
/// `workers` blocks at a time (worker 0 on the calling thread; the caller holds each
/// worker's state, sized by the same count: row_block_workers), and after each such round
/// add(worker) for the round's blocks in block order. An exception from a block is
/// rethrown once the round has ended (the earliest block's).
void over_row_blocks(std::size_t rows, int workers,
                     const std::function<void(int worker, std::size_t from, std::size_t to)>& work,
                     const std::function<void(int worker)>& add);

}  // namespace resolver
