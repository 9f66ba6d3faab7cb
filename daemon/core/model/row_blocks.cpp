#include "daemon/core/model/row_blocks.h"

#include <algorithm>
#include <atomic>
#include <exception>
#include <system_error>
#include <thread>
#include <vector>

namespace resolver {

namespace {
std::atomic<int> g_threads{1};
}  // namespace

void set_pass_threads(int threads) { g_threads.store(std::max(1, threads)); }

int pass_threads() { return g_threads.load(); }

int row_block_workers(std::size_t rows) {
  const std::size_t blocks = (rows + kRowBlock - 1) / kRowBlock;
  return static_cast<int>(std::clamp<std::size_t>(blocks, 1, static_cast<std::size_t>(pass_threads())));
}

void over_row_blocks(std::size_t rows, int worker_count,
                     const std::function<void(int worker, std::size_t from, std::size_t to)>& work,
                     const std::function<void(int worker)>& add) {
  const auto workers = static_cast<std::size_t>(std::max(1, worker_count));
  for (std::size_t first = 0; first < rows; first += workers * kRowBlock) {
    std::vector<std::exception_ptr> failed(workers);
    const auto run = [&](std::size_t w) {
      const std::size_t from = first + w * kRowBlock;
      if (from >= rows) return;
      try {
        work(static_cast<int>(w), from, std::min(rows, from + kRowBlock));
      } catch (...) {
        failed[w] = std::current_exception();
      }
    };
    std::vector<std::thread> others;
    others.reserve(workers - 1);
    try {
      for (std::size_t w = 1; w < workers; ++w) others.emplace_back(run, w);
    } catch (const std::system_error&) {
      // No thread to be had (a process or memory limit): the blocks of the workers that
      // did not start run here below, each with its worker's state, as they would have.
    }
    run(0);
    for (std::size_t w = others.size() + 1; w < workers; ++w) run(w);
    for (std::thread& t : others) t.join();
    for (const std::exception_ptr& e : failed) {
      if (e) std::rethrow_exception(e);
    }
    for (std::size_t w = 0; w < workers && first + w * kRowBlock < rows; ++w) add(static_cast<int>(w));
  }
}

}  // namespace resolver
