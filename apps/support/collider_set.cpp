#include "apps/support/collider_set.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace quiver::app {

namespace {

// Comma-separated finite numbers; false on anything else.
bool parseNumbers(const std::string& text, std::vector<double>& numbers) {
  std::stringstream in(text);
  for (std::string item; std::getline(in, item, ',');) {
    size_t used = 0;
    double x = 0;
    try {
      x = std::stod(item, &used);
    } catch (const std::exception&) {
      return false;
    }
    if (used != item.size() || !std::isfinite(x)) return false;
    numbers.push_back(x);
  }
  return true;
}

} // namespace

void ColliderSet::add(const std::string& text, double friction, double restitution) {
  static const struct {
    const char* name;
    qv_collider_type type;
    size_t count;
    const char* form;
  } kTypes[] = {{"plane", QV_COLLIDER_PLANE, 4, "nx,ny,nz,d"},
                {"sphere", QV_COLLIDER_SPHERE, 4, "x,y,z,radius"},
                {"box", QV_COLLIDER_BOX, 6, "cx,cy,cz,hx,hy,hz"},
                {"capsule", QV_COLLIDER_CAPSULE, 7, "x0,y0,z0,x1,y1,z1,radius"},
                {"mesh", QV_COLLIDER_MESH, 3, "FILE[,x,y,z]"}};
  const size_t colon = text.find(':');
  const std::string name = text.substr(0, colon), rest = colon == std::string::npos ? "" : text.substr(colon + 1);
  const std::string option = "--collider '" + text + "'";
  for (const auto& t : kTypes) {
    if (name != t.name) continue;
    const std::string bad = option + ": expected " + t.name + ":" + t.form;
    qv_collider c{};
    c.type = t.type;
    c.friction = friction;
    c.restitution = restitution;
    std::vector<double> numbers;
    std::unique_ptr<SurfaceMesh> surface;
    if (t.type == QV_COLLIDER_MESH) {
      // FILE, then optionally three numbers: the last three comma-separated items when they parse.
      std::string file = rest;
      const size_t c3 = rest.rfind(','), c2 = c3 == std::string::npos ? c3 : rest.rfind(',', c3 - 1),
                   c1 = c2 == std::string::npos || c2 == 0 ? std::string::npos : rest.rfind(',', c2 - 1);
      if (c1 != std::string::npos && parseNumbers(rest.substr(c1 + 1), numbers) && numbers.size() == 3) {
        file = rest.substr(0, c1);
      } else {
        numbers.assign(3, 0.0);
      }
      if (file.empty()) throw std::runtime_error(bad);
      try {
        surface = std::make_unique<SurfaceMesh>(readSurfaceFile(file));
      } catch (const std::exception& e) {
        throw std::runtime_error(option + ": " + e.what());
      }
      qv_triangle_mesh* mesh = nullptr;
      char message[512] = "";
      if (qv_triangle_mesh_create(surface->positions.data(), static_cast<int>(surface->positions.size() / 3),
                                  surface->triangles.data(), static_cast<int>(surface->triangles.size() / 3), nullptr,
                                  &mesh, message, sizeof message) != QV_OK)
        throw std::runtime_error(option + ": " + file + ": " + message);
      meshes_.emplace_back(mesh);
      c.mesh = mesh;
    } else if (!parseNumbers(rest, numbers) || numbers.size() != t.count) {
      throw std::runtime_error(bad);
    }
    std::copy(numbers.begin(), numbers.end(), c.data);
    colliders_.push_back(c);
    surfaces_.push_back(std::move(surface));
    return;
  }
  throw std::runtime_error(option + ": the type is plane, sphere, box, capsule or mesh");
}

} // namespace quiver::app
