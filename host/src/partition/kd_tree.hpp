#pragma once
// A k-d tree over key boxes whose leaves (cells) the accelerator processes.

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "partition.hpp"

namespace bpaccel {

/// Built anew every frame; all storage is kept and reused between builds, and
/// no node allocates. Memory: the leaves' item lists (every box once, plus
/// one entry per extra leaf a straddling box joins) and a work stack that
/// holds only the item lists of nodes still waiting to be split, so it never
/// keeps a whole level, let alone every level. Any object count the input
/// check accepts (kMaxObjects) can be indexed: lists are addressed with
/// 64-bit offsets. Cells partition key space into half-open boxes
/// [lo, hi). A box goes to a child whose region it touches (so a box that
/// straddles a split plane goes to both), which puts every box that contains
/// a point p into the one leaf whose region contains p.
class KdTree final : public Partition {
 public:
  using Leaf = Cell;
  /// Gets each leaf as soon as it is final, while the build goes on; its
  /// boxes come packed when the build carries them (see Layout).
  using LeafSink = CellSink;

  /// Splits until a cell holds at most `cellSize` boxes, or until no split
  /// helps (every plane is straddled by too many boxes): such a cell stays
  /// larger than cellSize and is chunked by the caller. Leaves come out in
  /// depth-first order; `onLeaf` (if any) gets each one as it is made, so a
  /// caller can process cells while the rest of the tree is being built.
  ///
  /// Layout: with Carried, each work item carries its box, so a split reads
  /// its boxes in sequence and a leaf's boxes come out packed; with Gathered,
  /// a split reads them from the scene by index. Carrying costs copies that
  /// only pay once the scene no longer fits in cache. Measured here (cell
  /// 128, tree build): 8000 boxes 0.36 ms gathered, 0.50 carried; 200,000
  /// boxes 20 ms and 24; 400,000 boxes 123 ms and 54; 10^6 boxes 673 ms and
  /// 153. Auto carries above kCarryAbove boxes. Both give the same leaves.
  enum class Layout { Auto, Carried, Gathered };
  static constexpr std::size_t kCarryAbove = 1 << 18;  // 6.3 MB of boxes
  void build(std::span<const KeyBox> boxes, std::size_t cellSize, const LeafSink& onLeaf, Layout layout);
  // The tree splits at medians and needs no bounds.
  void build(std::span<const KeyBox> boxes, std::size_t cellSize, const CellSink& onCell,
             const KeyBounds* = nullptr) override {
    build(boxes, cellSize, onCell, Layout::Auto);
  }
  std::string_view name() const override { return "k-d"; }
  bool streamsCells() const override { return true; }

  const std::vector<Leaf>& cells() const override { return leaves_; }
  /// Item entries the tree's buffers hold (their capacity): what its memory
  /// grows with. Each work and scratch entry also carries its box (24 bytes).
  std::size_t storedItems() const {
    return leafItems_.capacity() + work_.capacity() + left_.capacity() + right_.capacity();
  }
  /// Box indices of a leaf.
  std::span<const std::uint32_t> items(const Leaf& leaf) const override {
    return {leafItems_.data() + leaf.begin, leaf.count};
  }

 private:
  // A node waiting to be split: its items are work_[begin, begin + count),
  // and the node on top of the stack always owns the end of work_.
  struct Task {
    std::uint64_t begin;
    std::uint32_t count;
    std::array<std::uint64_t, 3> lo, hi;
  };
  template <bool kCarried>
  bool split(std::span<const KeyBox> boxes, const Task& task);

  std::vector<std::uint32_t> leafItems_;  // item lists of the leaves, in leaf order
  std::vector<std::uint32_t> work_;       // item lists of the nodes on stack_
  // Each work_ entry's box, beside it: a split reads its boxes in sequence
  // instead of gathering them from the scene (a cache miss each at 10^6 boxes).
  std::vector<KeyBox> workKeys_;
  std::vector<std::uint32_t> left_, right_;  // scratch: the children's items while splitting
  std::vector<KeyBox> leftKeys_, rightKeys_;
  std::vector<Task> stack_;
  std::vector<Leaf> leaves_;
};

}  // namespace bpaccel
