// Fuzzes the OBJ mesh reader and the mesh collider built from what it reads.
//
// The input is OBJ text, read at scale 1. A mesh that reads becomes a mesh collider (its grid is
// built then), which is asked for the distance at points around the mesh, near and far, with a
// short and a long reach. Checked: every distance is a number within 0..reach (a mesh is a shell:
// no inside) and every normal is a finite unit vector. Expected failures: InputError and
// std::invalid_argument; anything else escapes, and libFuzzer reports it.
#include <cmath>
#include <stdexcept>
#include <string>

#include <glm/geometric.hpp>

#include "drape/scene/error.hpp"
#include "drape/scene/obj.hpp"
#include "drape/sim/collider.hpp"
#include "fuzz_support.hpp"

using namespace drape;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    sim::ColliderSettings settings;
    settings.shape = sim::ColliderShape::mesh;
    settings.mesh = scene::parseObj(fuzz::text(data, size), "fuzz.obj", 1.0);
    const sim::TriangleMesh& mesh = *settings.mesh;
    const sim::Collider collider(settings);
    const glm::uvec3 first = mesh.triangles.front(), last = mesh.triangles.back();
    const sim::Vec3 a = mesh.vertices[first.x], b = mesh.vertices[first.y], c = mesh.vertices[first.z];
    const sim::Vec3 queries[] = {
        sim::Vec3{0.0},
        (a + b + c) / 3.0 + sim::Vec3{0.001, 0.002, -0.0015},
        a + sim::Vec3{0.03, -0.02, 0.01},
        mesh.vertices[last.y] + sim::Vec3{-0.2, 0.3, 0.1},
        (mesh.vertices[last.x] + mesh.vertices[last.z]) * 0.5,
        sim::Vec3{1.0e3, -2.0e3, 5.0e2},
    };
    for (const sim::Vec3& p : queries) {
      for (const sim::Real reach : {0.05, 2.0}) {
        const sim::SurfaceDistance d = collider.distance(p, reach);
        if (!(d.distance >= 0.0 && d.distance <= reach)) fuzz::broken("a mesh distance outside 0..reach");
        const sim::Real length = glm::length(d.normal);
        if (!(std::abs(length - 1.0) < 1e-9)) fuzz::broken("a mesh normal not a unit vector");
      }
    }
  } catch (const scene::InputError&) {
  } catch (const std::invalid_argument&) {
  }
  return 0;
}
