#pragma once
// Atomic file replacement: the bytes go to a temporary file in the same folder, are flushed, and
// the temporary is renamed over `path`. Readers never see a half-written file, and an existing
// file is left untouched when anything fails. Throws std::runtime_error naming the path.
#include <string>
#include <string_view>

namespace quiver {

void writeFileAtomically(const std::string& path, std::string_view bytes);

} // namespace quiver
