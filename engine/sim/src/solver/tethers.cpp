#include "solver/tethers.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

namespace drape::sim {

namespace {

using Tether = SolverScratch::Tethers::Tether;

// The pins of one piece in a uniform grid over their rest positions, about one pin a cell.
class PinGrid {
 public:
  PinGrid(const ClothRest& rest, const std::vector<ParticleIndex>& pins) : rest_(rest) {
    Vec3 lower{std::numeric_limits<Real>::max()}, upper{std::numeric_limits<Real>::lowest()};
    for (const ParticleIndex p : pins) {
      lower = glm::min(lower, rest.restPosition(p));
      upper = glm::max(upper, rest.restPosition(p));
    }
    const Vec3 extent = upper - lower;
    const Real widest = std::max({extent.x, extent.y, extent.z});
    int dimensions = 0;
    for (int axis = 0; axis < 3; ++axis) dimensions += extent[axis] > 1e-9 * widest ? 1 : 0;
    const Real perAxis = dimensions == 0 ? 1.0 : std::floor(std::pow(static_cast<Real>(pins.size()), 1.0 / dimensions));
    cell_ = widest > 0.0 ? widest / std::max<Real>(perAxis, 1.0) : 1.0;
    origin_ = lower;
    cells_ = glm::ivec3(glm::floor(extent / cell_)) + 1;
    // Counted, then filled, in pin order within a cell.
    start_.assign(static_cast<std::size_t>(cells_.x) * cells_.y * cells_.z + 1, 0);
    for (const ParticleIndex p : pins) ++start_[cellOf(clampedCell(rest.restPosition(p))) + 1];
    for (std::size_t c = 1; c < start_.size(); ++c) start_[c] += start_[c - 1];
    pins_.resize(pins.size());
    std::vector<std::uint32_t> filled(start_.begin(), start_.end() - 1);
    for (const ParticleIndex p : pins) pins_[filled[cellOf(clampedCell(rest.restPosition(p)))]++] = p;
  }

  // The `count` pins nearest to x (ties to the lower index), in ascending index order.
  void nearest(Vec3 x, std::size_t count, std::vector<ParticleIndex>& out) const {
    struct Candidate {
      Real distance2;
      ParticleIndex pin;
      bool operator<(const Candidate& o) const {
        return distance2 < o.distance2 || (distance2 == o.distance2 && pin < o.pin);
      }
    };
    std::vector<Candidate> best;  // sorted, at most `count`
    const glm::ivec3 centre = clampedCell(x);
    const Vec3 outside = x - glm::clamp(x, origin_, origin_ + Vec3(cells_) * cell_);
    const Real outside2 = glm::dot(outside, outside);
    const int widest = std::max({cells_.x, cells_.y, cells_.z});
    for (int ring = 0; ring <= widest; ++ring) {
      const glm::ivec3 from = glm::max(centre - ring, glm::ivec3(0));
      const glm::ivec3 to = glm::min(centre + ring, cells_ - 1);
      for (int z = from.z; z <= to.z; ++z) {
        for (int y = from.y; y <= to.y; ++y) {
          for (int cx = from.x; cx <= to.x; ++cx) {
            const glm::ivec3 c{cx, y, z};
            const glm::ivec3 offset = glm::abs(c - centre);
            if (std::max({offset.x, offset.y, offset.z}) != ring) continue;  // an inner ring's
            const std::size_t cell = cellOf(c);
            for (std::uint32_t k = start_[cell]; k < start_[cell + 1]; ++k) {
              const Vec3 d = rest_.restPosition(pins_[k]) - x;
              const Candidate candidate{glm::dot(d, d), pins_[k]};
              if (best.size() == count && !(candidate < best.back())) continue;
              best.insert(std::upper_bound(best.begin(), best.end(), candidate), candidate);
              if (best.size() > count) best.pop_back();
            }
          }
        }
      }
      // Every pin not yet seen lies in a cell at least ring + 1 cells from the cell of q, x clamped
      // into the grid's box, so at least ring cells from q; and as q is the point of the box
      // nearest to x, |x - pin|^2 >= |x - q|^2 + |q - pin|^2.
      const Real reach = static_cast<Real>(ring) * cell_;
      if (best.size() == count && best.back().distance2 < outside2 + reach * reach) break;
    }
    out.clear();
    for (const Candidate& c : best) out.push_back(c.pin);
    std::sort(out.begin(), out.end());
  }

 private:
  glm::ivec3 clampedCell(Vec3 x) const {
    const Vec3 at = glm::clamp(glm::floor((x - origin_) / cell_), Vec3{0.0}, Vec3(cells_ - 1));
    return glm::ivec3(at);
  }
  std::size_t cellOf(glm::ivec3 c) const {
    return (static_cast<std::size_t>(c.z) * static_cast<std::size_t>(cells_.y) + static_cast<std::size_t>(c.y)) *
               static_cast<std::size_t>(cells_.x) +
           static_cast<std::size_t>(c.x);
  }

  const ClothRest& rest_;
  Vec3 origin_{0.0};
  Real cell_ = 1.0;
  glm::ivec3 cells_{1};
  std::vector<std::uint32_t> start_;
  std::vector<ParticleIndex> pins_;
};

}  // namespace

std::vector<Tether> nearestPinTethers(const Cloth& cloth) {
  const ParticleState& s = cloth.state;
  std::vector<std::vector<ParticleIndex>> pinsOf(cloth.pieceCount);
  for (const ParticleIndex p : cloth.tetherPins) {
    if (s.pinned[p]) pinsOf[cloth.pieceOf(p)].push_back(p);
  }
  std::vector<std::optional<PinGrid>> grids(cloth.pieceCount);
  for (std::size_t piece = 0; piece < pinsOf.size(); ++piece) {
    if (pinsOf[piece].size() > kMaxTethersPerParticle) grids[piece].emplace(cloth.rest, pinsOf[piece]);
  }
  // Particle by particle, so that a particle's tethers are consecutive and projected together.
  // Every particle not pinned has them, a held one too (the tethers skip it while it is held).
  std::vector<Tether> tethers;
  std::vector<ParticleIndex> chosen;
  for (std::size_t i = 0; i < s.position.size(); ++i) {
    if (s.pinned[i]) continue;
    const std::uint32_t piece = cloth.pieceOf(i);
    const Vec3 x = cloth.rest.restPosition(i);
    if (grids[piece]) {
      grids[piece]->nearest(x, kMaxTethersPerParticle, chosen);
    } else {
      chosen = pinsOf[piece];
    }
    for (const ParticleIndex p : chosen) {
      // As far from the pin as it is at rest (Euclidean: never shorter than the path in the cloth),
      // rounded up, not to the nearest float: the rest shape must lie inside every tether, and
      // where two pins' balls only just touch (the top row between them) a rounding down leaves
      // no point in both.
      const RestReal length = toRestLengthAtLeast(glm::length(x - cloth.rest.restPosition(p)));
      tethers.push_back({static_cast<ParticleIndex>(i), p, length});
    }
  }
  return tethers;
}

}  // namespace drape::sim
