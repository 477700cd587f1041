// Output folders a command creates (`--out DIR` and the like). A command that is refused or fails
// part-way must not leave behind a folder that did not exist before it ran, empty or holding part
// of a result: the folders created here are remembered, and the entry point removes them when the
// command ends with an error (pipeline/cli/main.cpp). Folders that existed before are never removed.
#pragma once

#include <filesystem>
#include <string_view>

namespace nbsim::io {

// Creates `dir` and any missing parent; remembers the outermost folder it created. Throws
// InputError naming `what` and the folder when it cannot be created.
void create_output_folder(const std::filesystem::path& dir, std::string_view what = "output folder");

// The command's outputs are a result from here on (kept whatever happens next).
void keep_output_folders() noexcept;

// Removes, with their contents, the folders create_output_folder created and that were not kept.
void remove_created_output_folders() noexcept;

}  // namespace nbsim::io
