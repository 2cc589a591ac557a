#pragma once
// Errors raised while reading, validating or writing mesh files. The message is complete and
// names the file and the place ("beam.msh:120: ..." or "beam.msh: byte 4096: ...").
#include <stdexcept>
#include <string>

namespace quiver {

class MeshError : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

} // namespace quiver
