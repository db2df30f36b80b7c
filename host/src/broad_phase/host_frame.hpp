#pragma once
// A frame of the cpu backend, run by the broad phase itself on the host's
// threads: conversion, partition and cells on one thread pool, each cell's
// pairs found and filtered in one step.

#include <memory>
#include <span>
#include <vector>

#include "../core/all_pairs_kernel.hpp"
#include "../core/thread_pool.hpp"
#include "../core/types.hpp"
#include "../partition/automatic_choice.hpp"
#include "../partition/partition.hpp"
#include "broad_phase_config.hpp"
#include "frame_observer.hpp"

namespace bpaccel {

/// The broad phase on a backend whose hostKernel() it runs itself (the cpu
/// backend). Every part shares config.threads threads:
/// - the conversion to keys and the scene's bounds, a part of the boxes a thread;
/// - the partition: the grid counts and places its items a part a thread
///   (UniformGrid::buildIndex); the k-d tree is built on the calling thread;
/// - the cells, a task each, each thread with its own scratch and pairs:
///   a cell's boxes are read from the keys by its items, the kernel that
///   fits its size tests them (AllPairsKernel::ownedPairs), and only the
///   pairs the cell owns (below() bits, or the region's for the tree) come
///   out, as scene indices; the threads' pairs are then joined.
/// With an automatic cell size the partition and the cell size are chosen
/// for each frame (AutomaticChoice).
class HostFrame {
 public:
  HostFrame(const AllPairsKernel& kernel, const BroadPhaseConfig& config);
  ~HostFrame();
  HostFrame(const HostFrame&) = delete;
  HostFrame& operator=(const HostFrame&) = delete;

  /// Appends the pairs (i < j, unsorted) to `out` (cleared first).
  void findPairs(std::span<const Aabb> boxes, std::vector<Pair>& out);
  void findPairs(std::span<const KeyBox> keys, std::vector<Pair>& out);

  /// The last frame's: cells run (runs and batches), pairs found (hits).
  const RunStats& stats() const { return stats_; }
  /// The last frame's partition (for the scene as one cell, the grid's one cell).
  const Partition& partition() const { return *used_; }
  /// The last frame's choice of partition and cell size.
  const CellChoice& choice() const { return choice_; }
  /// With an observer: the last frame's timing (no hand-overs; all host work).
  const FrameTiming& timing() const { return timing_; }
  std::size_t threads() const { return pool_.threads(); }

 private:
  struct Local;
  void findKeyPairs(std::span<const KeyBox> keys, const KeyBounds* bounds, std::vector<Pair>& out);
  CellChoice choose(std::span<const KeyBox> keys, const KeyBounds& bounds);
  void runCells(std::span<const KeyBox> keys);
  void runCell(std::span<const KeyBox> keys, const Cell& cell, Local& local) const;
  void join(std::vector<Pair>& out);

  AllPairsKernel kernel_;
  BroadPhaseConfig config_;
  ThreadPool pool_;
  std::unique_ptr<Partition> tree_, grid_;
  Partition* used_;
  AutomaticChoice chooser_{SizeRule::MeanCellBand};  // the kernel sets the best cell size
  CellChoice choice_;
  std::vector<KeyBox> keys_;
  std::vector<Local> locals_;  // one per thread
  RunStats stats_;
  FrameTiming timing_;
};

}  // namespace bpaccel
