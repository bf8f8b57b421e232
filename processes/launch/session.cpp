#include "session.hpp"

#include <filesystem>

namespace fs = std::filesystem;

namespace traverse::launch {

std::optional<std::string> prepare_state(const std::string& out_dir, const std::string& resume) {
  const fs::path state = fs::path(out_dir) / "state";
  std::error_code ec;
  if (resume.empty()) {
    fs::remove_all(state, ec);
    return ec ? std::optional<std::string>("cannot clear " + state.string() + ": " + ec.message())
              : std::nullopt;
  }
  const fs::path saved = fs::path(resume) / "state";
  if (!fs::is_directory(saved)) return "--resume " + resume + ": no saved state (no state/ there)";
  if (fs::weakly_canonical(resume, ec) == fs::weakly_canonical(out_dir, ec)) {
    return "--resume " + resume +
           " is --out itself: a resumed session writes into a new folder, "
           "so that the earlier run's log and exports stay as they were";
  }
  fs::remove_all(state, ec);
  fs::create_directories(state.parent_path(), ec);
  fs::copy(saved, state, fs::copy_options::recursive, ec);
  if (ec) return "cannot copy " + saved.string() + " to " + state.string() + ": " + ec.message();
  return std::nullopt;
}

}  // namespace traverse::launch
