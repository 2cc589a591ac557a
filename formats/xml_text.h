#pragma once
// Text for XML attributes and content: file names and field names the user chose, in the .vtu,
// .pvd and .xmf files ParaView reads.
#include <string>
#include <string_view>

namespace quiver {

// `text` with & < > " ' as entities.
std::string escapeXml(std::string_view text);

} // namespace quiver
