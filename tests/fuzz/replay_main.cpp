// Corpus replay driver: links a fuzz target's LLVMFuzzerTestOneInput into a
// plain executable (any compiler, no libFuzzer) so ctest runs every checked-in
// input through the same checks the fuzzer applies.
//
//   fuzz_<target>_replay PATH...    PATH: a file, or a folder (its regular files,
//                                   not recursive, in name order)
// Exit 0 when every input ran (a broken property aborts the process), 1 when a
// path is unreadable or no input was found (an empty run proves nothing).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <string>
#include <system_error>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace {

bool run_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    std::cerr << "fuzz replay: cannot read " << path.string() << "\n";
    return false;
  }
  const std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  // Copy into an exactly sized heap block so ASan (when enabled) sees reads past the end.
  std::vector<std::uint8_t> input(bytes.begin(), bytes.end());
  std::cerr << "fuzz replay: " << path.string() << " (" << input.size() << " bytes)\n";
  LLVMFuzzerTestOneInput(input.empty() ? nullptr : input.data(), input.size());
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::cerr << "usage: " << argv[0] << " FILE_OR_FOLDER...\n";
    return 1;
  }
  std::size_t ran = 0;
  for (int i = 1; i < argc; ++i) {
    const std::filesystem::path arg(argv[i]);
    std::error_code ec;
    if (std::filesystem::is_directory(arg, ec)) {
      std::vector<std::filesystem::path> files;
      for (const auto& entry : std::filesystem::directory_iterator(arg, ec)) {
        if (entry.is_regular_file()) files.push_back(entry.path());
      }
      if (ec) {
        std::cerr << "fuzz replay: cannot list " << arg.string() << ": " << ec.message() << "\n";
        return 1;
      }
      std::sort(files.begin(), files.end());
      for (const auto& f : files) {
        if (!run_file(f)) return 1;
        ++ran;
      }
    } else {
      if (!run_file(arg)) return 1;
      ++ran;
    }
  }
  if (ran == 0) {
    std::cerr << "fuzz replay: no input files found\n";
    return 1;
  }
  std::cout << "fuzz replay: " << ran << " inputs, no property broken\n";
  return 0;
}
