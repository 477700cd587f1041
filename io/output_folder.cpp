// Output folders removed again when a command fails; see output_folder.h.
#include "io/output_folder.h"

#include <fmt/format.h>

#include <mutex>
#include <system_error>
#include <vector>

#include "model/common/error.h"

namespace nbsim::io {
namespace {

std::mutex mutex;
std::vector<std::filesystem::path>& created() {
  static std::vector<std::filesystem::path> folders;
  return folders;
}

}  // namespace

void create_output_folder(const std::filesystem::path& dir, std::string_view what) {
  // The outermost missing folder on the way to `dir`: removing it removes everything created here.
  std::filesystem::path outermost;
  std::error_code ec;
  for (std::filesystem::path p = std::filesystem::absolute(dir, ec).lexically_normal(); !ec && !p.empty();
       p = p.parent_path()) {
    if (std::filesystem::exists(p, ec) || ec) break;
    outermost = p;
    if (p == p.parent_path()) break;
  }
  ec.clear();
  std::filesystem::create_directories(dir, ec);
  if (ec || !std::filesystem::is_directory(dir))
    throw InputError(fmt::format("cannot create {} '{}': {}", what, dir.string(),
                                 ec ? ec.message() : "a file of that name is in the way"));
  if (!outermost.empty()) {
    const std::lock_guard lock(mutex);
    created().push_back(outermost);
  }
}

void keep_output_folders() noexcept {
  const std::lock_guard lock(mutex);
  created().clear();
}

void remove_created_output_folders() noexcept {
  const std::lock_guard lock(mutex);
  for (auto it = created().rbegin(); it != created().rend(); ++it) {
    std::error_code ec;
    std::filesystem::remove_all(*it, ec);
  }
  created().clear();
}

}  // namespace nbsim::io
