// Triangle meshes from Wavefront OBJ text, for mesh colliders.
#pragma once

#include <cstddef>
#include <memory>
#include <string>
#include <string_view>

#include "drape/sim/collider.hpp"

namespace drape::scene {

inline constexpr std::size_t kMaxMeshTriangles = std::size_t{1} << 21;  // after triangulation
inline constexpr double kMaxMeshCoordinate = 1.0e4;                     // m, after scaling

// The mesh's vertices (times `scale`) and faces, polygons split into triangles. Normals, texture
// coordinates and materials are ignored: an `mtllib` line is never followed. `what` starts every
// message ("scene.json: colliders.0.file: cannot use the OBJ file box.obj"). Throws InputError when
// the text is malformed, has no triangles or more than kMaxMeshTriangles, a face names a vertex it
// does not have, or a vertex lies beyond kMaxMeshCoordinate.
std::shared_ptr<const sim::TriangleMesh> parseObj(std::string_view text, const std::string& what, double scale);

}  // namespace drape::scene
