#pragma once
// Result files are written to a temporary name in the same folder and renamed into place,
// so a failed run never leaves a half-written or corrupted result behind.
#include <filesystem>
#include <string>

namespace shroudsim::io {

/// Writes `content` to `path` atomically (temporary file + rename). Creates parent folders.
void write_file_atomic(const std::filesystem::path& path, const std::string& content);

/// Formats a double for CSV/JSON with round-trip precision; throws NumericalError on NaN/Inf
/// (no NaN ever reaches a result file).
std::string format_number(double value);

}  // namespace shroudsim::io
