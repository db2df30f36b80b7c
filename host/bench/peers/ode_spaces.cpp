#include "ode_spaces.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>

#include <fmt/format.h>

#include <ode/ode.h>

namespace bpaccel {
namespace {

// ODE's library is initialised per user; dInitODE2 and dCloseODE are counted by ODE.
class OdeLibrary {
 public:
  OdeLibrary() {
    if (!dInitODE2(0)) throw std::runtime_error("ode: dInitODE2 failed");
  }
  ~OdeLibrary() { dCloseODE(); }
  OdeLibrary(const OdeLibrary&) = delete;
  OdeLibrary& operator=(const OdeLibrary&) = delete;
};

// A box geom centred on the AABB with its edges: with the identity rotation
// ODE's AABB of it is the box again, exactly (all the arithmetic is exact in double).
void place(dGeomID geom, const Aabb& b) {
  const dReal cx = (dReal(b.min[0]) + b.max[0]) / 2, cy = (dReal(b.min[1]) + b.max[1]) / 2,
              cz = (dReal(b.min[2]) + b.max[2]) / 2;
  dGeomBoxSetLengths(geom, dReal(b.max[0]) - b.min[0], dReal(b.max[1]) - b.min[1], dReal(b.max[2]) - b.min[2]);
  dGeomSetPosition(geom, cx, cy, cz);
}

void recordPair(void* data, dGeomID a, dGeomID b) {
  const auto i = static_cast<std::uint32_t>(reinterpret_cast<std::uintptr_t>(dGeomGetData(a)));
  const auto j = static_cast<std::uint32_t>(reinterpret_cast<std::uintptr_t>(dGeomGetData(b)));
  static_cast<std::vector<Pair>*>(data)->emplace_back(std::min(i, j), std::max(i, j));
}

}  // namespace

std::optional<std::string> hashSpaceSkipReason(std::size_t objects) {
  // dxHashSpace::collide keeps one bit per pair of geoms, tested or not, in a
  // table of n * ceil(n/8) bytes sized and indexed with int: beyond INT_MAX
  // bytes (n > 131,071) it throws from inside the locked space, or asserts,
  // and ODE aborts the process either way (seen at 300,000 and 1,000,000).
  const double n = static_cast<double>(objects);
  const double bytes = n * std::ceil(n / 8);
  if (bytes <= static_cast<double>(std::numeric_limits<int>::max())) return std::nullopt;
  return fmt::format("its collide sizes a table of one bit per pair ({:.1f} GB here) with int arithmetic, which "
                     "overflows above 131,071 objects: ODE 0.16 aborts the process",
                     bytes / 1e9);
}

struct OdeSpace::Impl {
  OdeLibrary library;
  dSpaceID space = nullptr;
  std::vector<dGeomID> geoms;
  ~Impl() {
    if (space) dSpaceDestroy(space);  // destroys its geoms too (cleanup mode is on by default)
  }
};

OdeSpace::OdeSpace(Kind kind, const SceneStart& start) : impl_(std::make_unique<Impl>()) {
  if (kind == Kind::Hash) {
    impl_->space = dHashSpaceCreate(nullptr);
    // Cells of 2^min to 2^max: the manual's advice is to span the geoms' sizes,
    // from the smallest AABB side to the largest.
    double smallest = INFINITY, largest = 0;
    for (const Aabb& b : start.boxes)
      for (int a = 0; a < 3; ++a) {
        const double side = static_cast<double>(b.max[a]) - b.min[a];
        smallest = std::min(smallest, side);
        largest = std::max(largest, side);
      }
    const int lo = smallest > 0 && std::isfinite(smallest) ? static_cast<int>(std::floor(std::log2(smallest))) : -3;
    const int hi = largest > 0 ? static_cast<int>(std::ceil(std::log2(largest))) : lo;
    dHashSpaceSetLevels(impl_->space, lo, std::max(lo, hi));
  } else {
    // The scene is a cube with no preferred axis, so the default order.
    impl_->space = dSweepAndPruneSpaceCreate(nullptr, dSAP_AXES_XYZ);
  }
  impl_->geoms.reserve(start.boxes.size());
  for (std::size_t i = 0; i < start.boxes.size(); ++i) {
    dGeomID g = dCreateBox(impl_->space, 1, 1, 1);
    dGeomSetData(g, reinterpret_cast<void*>(static_cast<std::uintptr_t>(i)));
    place(g, start.boxes[i]);
    impl_->geoms.push_back(g);
  }
}

OdeSpace::~OdeSpace() = default;

void OdeSpace::update(std::span<const Aabb> boxes) {
  if (boxes.size() != impl_->geoms.size()) throw std::invalid_argument("ode: object count changed");
  for (std::size_t i = 0; i < boxes.size(); ++i) place(impl_->geoms[i], boxes[i]);
  pairs_.clear();
  dSpaceCollide(impl_->space, &pairs_, recordPair);
}

std::vector<MethodSpec> odeMethods(double maxSweepTests) {
  std::vector<MethodSpec> specs;
  const std::pair<OdeSpace::Kind, const char*> kinds[] = {{OdeSpace::Kind::Hash, "ODE dHashSpace"},
                                                          {OdeSpace::Kind::SweepAndPrune, "ODE dSweepAndPruneSpace"}};
  for (const auto& [kind, name] : kinds) {
    MethodSpec s;
    s.name = name;
    s.kind = MethodKind::Peer;
    s.library = "ODE 0.16";
    // Every collide of the sweep-and-prune space is one sweep along x
    // (BoxPruning) that max-method-seconds cannot stop midway.
    if (kind == OdeSpace::Kind::SweepAndPrune) s.skipReason = sweepSkipReason(maxSweepTests);
    if (kind == OdeSpace::Kind::Hash)
      s.skipReason = [](const SceneStart& start) { return hashSpaceSkipReason(start.boxes.size()); };
    s.make = [kind](const SceneStart& start) { return std::make_unique<OdeSpace>(kind, start); };
    specs.push_back(std::move(s));
  }
  return specs;
}

}  // namespace bpaccel
