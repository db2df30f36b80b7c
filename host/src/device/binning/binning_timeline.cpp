#include "binning_timeline.hpp"

#include <algorithm>
#include <deque>
#include <optional>
#include <stdexcept>

#include <fmt/format.h>

namespace bpaccel::binning {
namespace {

using Cycle = std::uint64_t;

/// The intake: beats of boxes into per-group and per-lane queues, one entry
/// written a cycle per group (BinningCycleModel's "Intake").
class Intake {
 public:
  Intake(const BinningParams& p, const FrameCommand& f, const Binned& binned);
  /// Plays one cycle; true when it is the intake's last (T).
  bool step();
  std::vector<std::uint64_t> written;  // entries each group has written
  std::uint64_t boxesReceived = 0;

 private:
  bool beatErrs(std::size_t k) const;
  /// Beat k's entries: for each group, the lanes (rising) of its boxes with an entry there.
  const std::vector<std::vector<std::uint8_t>>& beatEntries(std::size_t k);

  const BinningParams& p_;
  std::vector<std::pair<std::size_t, std::size_t>> beats_;  // [first box, end)
  std::vector<std::vector<std::uint16_t>> boxGroups_;       // the groups each binned box writes
  std::optional<std::uint64_t> erring_;
  bool lengthMismatch_ = false;
  std::size_t sent_ = 0;
  std::vector<std::vector<std::uint32_t>> laneQ_;           // [group][lane]: entries queued
  std::vector<std::deque<std::vector<std::uint8_t>>> beatQ_;
  std::vector<std::size_t> headDone_;
  std::vector<std::vector<std::uint8_t>> scratch_;
  std::size_t nextBeat_ = 0;
  std::optional<std::size_t> register_;
  bool errorRaised_ = false, lastTaken_ = false, wroteLast_ = false;
};

Intake::Intake(const BinningParams& p, const FrameCommand& f, const Binned& binned)
    : written(p.groups()), p_(p), boxGroups_(f.boxes.size()), sent_(f.boxes.size()),
      laneQ_(p.groups(), std::vector<std::uint32_t>(p.intakeBoxes)), beatQ_(p.groups()), headDone_(p.groups()),
      scratch_(p.groups()) {
  if (f.boxes.empty()) beats_.emplace_back(0, 0);
  for (std::size_t b = 0; b < f.boxes.size(); b += p.intakeBoxes)
    beats_.emplace_back(b, std::min(f.boxes.size(), b + p.intakeBoxes));
  for (std::size_t gr = 0; gr < binned.groups.size(); ++gr)
    for (const Entry& e : binned.groups[gr]) boxGroups_[e.box].push_back(static_cast<std::uint16_t>(gr));
  errorRaised_ = binned.error == FrameError::CountOverCapacity || binned.error == FrameError::BadGrid;
  if (!binned.ok() && !errorRaised_) erring_ = binned.detail;
  lengthMismatch_ = binned.error == FrameError::LengthMismatch;
}

bool Intake::beatErrs(std::size_t k) const {
  if (!erring_) return false;
  const auto [first, end] = beats_[k];
  return (*erring_ >= first && *erring_ < end) || (k + 1 == beats_.size() && lengthMismatch_ && *erring_ == sent_);
}

const std::vector<std::vector<std::uint8_t>>& Intake::beatEntries(std::size_t k) {
  for (auto& lanes : scratch_) lanes.clear();
  for (std::size_t box = beats_[k].first; box < beats_[k].second; ++box)
    for (std::uint16_t gr : boxGroups_[box]) scratch_[gr].push_back(static_cast<std::uint8_t>(box - beats_[k].first));
  return scratch_;
}

bool Intake::step() {
  const bool quiet = lastTaken_ && !register_ && !wroteLast_ &&
                     std::all_of(beatQ_.begin(), beatQ_.end(), [](const auto& q) { return q.empty(); });
  if (quiet) return true;
  const bool regErrs = register_ && !errorRaised_ && beatErrs(*register_);
  const bool pushes = register_ && !errorRaised_ && !regErrs;
  if (pushes) beatEntries(*register_);
  bool regMoves = register_.has_value();
  for (unsigned gr = 0; pushes && gr < p_.groups(); ++gr) {
    if (scratch_[gr].empty()) continue;
    if (beatQ_[gr].size() >= p_.beatQueueDepth) regMoves = false;
    for (std::uint8_t lane : scratch_[gr])
      if (laneQ_[gr][lane] >= p_.laneQueueDepth) regMoves = false;
  }
  const bool takes = !lastTaken_ && (!register_ || regMoves) && nextBeat_ < beats_.size();
  bool wrote = false;
  for (unsigned gr = 0; gr < p_.groups(); ++gr) {  // each group writes its head beat's next entry
    if (beatQ_[gr].empty()) continue;
    const auto& head = beatQ_[gr].front();
    laneQ_[gr][head[headDone_[gr]]] -= 1;
    written[gr] += 1;
    wrote = true;
    if (++headDone_[gr] == head.size()) beatQ_[gr].pop_front(), headDone_[gr] = 0;
  }
  if (regMoves) {
    errorRaised_ = errorRaised_ || regErrs;
    for (unsigned gr = 0; pushes && gr < p_.groups(); ++gr) {
      if (scratch_[gr].empty()) continue;
      beatQ_[gr].push_back(scratch_[gr]);
      for (std::uint8_t lane : scratch_[gr]) laneQ_[gr][lane] += 1;
    }
    register_.reset();
  }
  if (takes) {
    register_ = nextBeat_;
    boxesReceived += beats_[nextBeat_].second - beats_[nextBeat_].first;
    lastTaken_ = ++nextBeat_ == beats_.size();
  }
  wroteLast_ = wrote;
  return false;
}

/// One stream item of a group: entry p of a cell of n entries, streamed in block `block`.
struct Item {
  std::uint32_t cell, p, block, n;
  bool first() const { return block == 0 && p == 0; }
  std::uint32_t left() const { return n - 1 - p; }
};

/// What a group does in one cycle, decided from the cycle's start.
struct GroupStep {
  bool walk = false, readItem = false, takeCell = false, op = false, fill = false, done = false;
  std::int64_t returned = -1;
};

/// One group after the intake: walker, reader, window and hit queue (BinningCycleModel's groups).
class GroupTimeline {
 public:
  GroupTimeline(const BinningParams& p, const GroupSchedule& s) : p_(p), s_(s) {}
  GroupStep decide() const;
  void commit(Cycle t, const GroupStep& step);
  bool hasHits() const { return !hitQ_.empty(); }
  /// The head hit beat's next pair, given to the merge.
  Pair takeHit();
  bool idle() const { return hitQ_.empty(); }
  std::size_t opsDone() const { return opIndex_; }
  Cycle computeAt = 0;
  std::optional<Cycle> done;

 private:
  void streamCell(std::uint32_t cell);

  const BinningParams& p_;
  const GroupSchedule& s_;
  std::uint32_t walkNext_ = 0;
  std::int64_t walkRead_ = -1;  // the cell read in the last cycle, returning in this one
  std::deque<std::uint32_t> cellQ_;
  std::deque<Item> pending_;                        // the rest of the current cell's stream
  std::deque<std::pair<Cycle, Item>> itemReads_;    // (cycle it is queued, item)
  std::deque<Item> itemQ_, window_;
  std::deque<std::pair<Cycle, std::uint32_t>> issuesLive_;  // (cycle its hits are queued, op)
  std::deque<std::uint32_t> hitQ_;                  // ops with hits
  std::uint32_t hitSent_ = 0;
  std::size_t opIndex_ = 0;
};

GroupStep GroupTimeline::decide() const {
  GroupStep s;
  const std::size_t lc = s_.cellSizes.size();
  s.returned = walkRead_;
  s.walk = walkNext_ < lc && cellQ_.size() + (walkRead_ >= 0 ? 1 : 0) < p_.cellQueueDepth;
  const bool mayRead = itemQ_.size() + itemReads_.size() < p_.itemQueueDepth;
  s.takeCell = mayRead && pending_.empty() && !cellQ_.empty();
  s.readItem = mayRead && (!pending_.empty() || !cellQ_.empty());
  const bool noMore = walkNext_ >= lc && walkRead_ < 0 && cellQ_.empty() && pending_.empty() && itemReads_.empty() &&
                      itemQ_.empty();
  // A schedule cycle needs every item it compares in the window, and room for its hits unless it is a bubble.
  s.op = !window_.empty() && window_.size() > std::min<std::size_t>(window_.front().left(), p_.lanesPerGroup - 1) &&
         (window_.front().first() || hitQ_.size() + issuesLive_.size() < p_.hitQueueDepth);
  s.fill = window_.size() - (s.op ? 1 : 0) < p_.lanesPerGroup && !itemQ_.empty();
  s.done = noMore && window_.empty() && issuesLive_.empty();
  return s;
}

void GroupTimeline::streamCell(std::uint32_t cell) {
  const std::uint32_t n = s_.cellSizes[cell], g = p_.lanesPerGroup;
  for (std::uint32_t b = 0; b <= (n - 2) / g; ++b)
    for (std::uint32_t q = b == 0 ? 0 : b * g + 1; q < n; ++q) pending_.push_back({cell, q, b, n});
}

void GroupTimeline::commit(Cycle t, const GroupStep& step) {
  if (step.done && !done) done = t;
  walkRead_ = step.walk ? static_cast<std::int64_t>(walkNext_++) : -1;
  if (step.takeCell) {
    streamCell(cellQ_.front());
    cellQ_.pop_front();
  }
  if (step.readItem) {
    itemReads_.emplace_back(t + 2 * p_.memoryReadLatency, pending_.front());
    pending_.pop_front();
  }
  if (step.returned >= 0 && s_.cellSizes[step.returned] >= 2) cellQ_.push_back(static_cast<std::uint32_t>(step.returned));
  if (step.op) {
    if (opIndex_ >= s_.ops.size() || s_.ops[opIndex_].bubble != window_.front().first())
      throw std::logic_error(fmt::format("binning timeline: the stream and the schedule disagree at op {}", opIndex_));
    if (!s_.ops[opIndex_].bubble) issuesLive_.emplace_back(t + p_.hitLatency, static_cast<std::uint32_t>(opIndex_));
    ++opIndex_;
    window_.pop_front();
  }
  if (step.fill) {
    window_.push_back(itemQ_.front());
    itemQ_.pop_front();
  }
  for (; !itemReads_.empty() && itemReads_.front().first == t; itemReads_.pop_front())
    itemQ_.push_back(itemReads_.front().second);
  for (; !issuesLive_.empty() && issuesLive_.front().first == t; issuesLive_.pop_front()) {
    const Op& op = s_.ops[issuesLive_.front().second];
    if (op.hitEnd > op.hitBegin) hitQ_.push_back(issuesLive_.front().second);
  }
}

Pair GroupTimeline::takeHit() {
  const Op& op = s_.ops[hitQ_.front()];
  const Pair pair = s_.hits[op.hitBegin + hitSent_];
  if (op.hitBegin + ++hitSent_ == op.hitEnd) hitQ_.pop_front(), hitSent_ = 0;
  return pair;
}

/// The merge: P clusters (cluster c serves groups c, c + P, ...), each taking
/// one pair a cycle round-robin, and the output queue of P-pair beats.
class OutputPath {
 public:
  explicit OutputPath(const BinningParams& p) : p_(p), lastGrant_(p.pairsPerBeat, -1), clusterQ_(p.pairsPerBeat) {}
  bool empty(const std::vector<GroupTimeline>& groups) const;
  /// One cycle: decisions from `groups` as they stood at the cycle's start (call before they commit).
  void decide(const std::vector<GroupTimeline>& groups);
  void commit(std::vector<GroupTimeline>& groups, std::vector<Pair>& sent);

 private:
  const BinningParams& p_;
  std::vector<int> lastGrant_;
  std::vector<std::deque<Pair>> clusterQ_;
  std::deque<std::vector<Pair>> outQ_;
  std::vector<std::pair<unsigned, unsigned>> grants_;  // (cluster, group)
  bool moveOut_ = false;
};

bool OutputPath::empty(const std::vector<GroupTimeline>& groups) const {
  return outQ_.empty() && std::all_of(clusterQ_.begin(), clusterQ_.end(), [](const auto& q) { return q.empty(); }) &&
         std::all_of(groups.begin(), groups.end(), [](const GroupTimeline& g) { return g.idle(); });
}

void OutputPath::decide(const std::vector<GroupTimeline>& groups) {
  moveOut_ = outQ_.size() < p_.mergeQueueDepth &&
             std::any_of(clusterQ_.begin(), clusterQ_.end(), [](const auto& q) { return !q.empty(); });
  grants_.clear();
  for (unsigned c = 0; c < p_.pairsPerBeat; ++c) {
    if (clusterQ_[c].size() >= p_.mergeQueueDepth) continue;
    int first = -1, after = -1;
    for (unsigned k = 0, gr = c; gr < groups.size(); ++k, gr += p_.pairsPerBeat) {
      if (!groups[gr].hasHits()) continue;
      if (first < 0) first = static_cast<int>(k);
      if (after < 0 && static_cast<int>(k) > lastGrant_[c]) after = static_cast<int>(k);
    }
    if (first >= 0) grants_.emplace_back(c, static_cast<unsigned>(after >= 0 ? after : first));
  }
}

void OutputPath::commit(std::vector<GroupTimeline>& groups, std::vector<Pair>& sent) {
  if (!outQ_.empty()) {  // the consumer is always ready
    sent.insert(sent.end(), outQ_.front().begin(), outQ_.front().end());
    outQ_.pop_front();
  }
  if (moveOut_) {
    std::vector<Pair> beat;
    for (auto& q : clusterQ_)
      if (!q.empty()) beat.push_back(q.front()), q.pop_front();
    outQ_.push_back(std::move(beat));
  }
  for (const auto& [c, k] : grants_) {
    clusterQ_[c].push_back(groups[c + k * p_.pairsPerBeat].takeHit());
    lastGrant_[c] = static_cast<int>(k);
  }
}

void summarize(const Binned& binned, PlayedFrame& played) {
  FrameReply& r = played.reply;
  for (const auto& g : binned.groups) {
    r.entries += g.size();
    r.fullestGroup = std::max<std::uint64_t>(r.fullestGroup, g.size());
  }
  if (!binned.ok()) return;
  const auto worst = static_cast<std::size_t>(
      std::max_element(played.groupDone.begin(), played.groupDone.end()) - played.groupDone.begin());
  const auto last = played.groupDone[worst];
  r.phases.intake = played.intakeDone + 1;
  r.phases.prefix = played.sortStart[worst] - played.intakeDone - 1;
  r.phases.sort = played.computeStart[worst] - played.sortStart[worst];
  r.phases.compute = last - played.computeStart[worst];
  r.phases.drain = r.cycles - last;
}

}  // namespace

PlayedFrame playFrame(const BinningParams& p, const FrameCommand& f, const Binned& binned,
                      const std::vector<GroupSchedule>& schedules, Cycle maxCycles) {
  PlayedFrame played;
  FrameReply& r = played.reply;
  r.error = binned.error;
  r.detail = binned.detail;
  Intake intake(p, f, binned);
  std::vector<GroupTimeline> groups;
  for (const auto& s : schedules) groups.emplace_back(p, s);
  OutputPath output(p);
  std::vector<GroupStep> steps(groups.size());
  std::optional<Cycle> intakeDone, finished;
  for (Cycle t = 1; !finished; ++t) {
    if (t > maxCycles) throw std::logic_error(fmt::format("binning timeline: no end within {} cycles", maxCycles));
    const bool afterIntake = intakeDone && binned.ok();
    for (std::size_t g = 0; g < groups.size(); ++g)
      steps[g] = afterIntake && t >= groups[g].computeAt && !groups[g].done ? groups[g].decide() : GroupStep{};
    output.decide(groups);
    const bool outputEmpty = output.empty(groups);
    if (!intakeDone && intake.step()) {
      intakeDone = t;
      if (!binned.ok()) finished = t + p.localCells();  // the cell tables are cleared, a row a cycle
      const auto local = p.localDims(f.dims);
      for (std::size_t g = 0; g < groups.size(); ++g)
        groups[g].computeAt = t + 1 + std::uint64_t{local[0]} * local[1] * local[2] + intake.written[g] +
                              p.memoryReadLatency + 1;
    }
    for (std::size_t g = 0; g < groups.size(); ++g) groups[g].commit(t, steps[g]);
    output.commit(groups, r.pairs);
    const bool allDone = std::all_of(groups.begin(), groups.end(), [](const auto& g) { return g.done.has_value(); });
    if (!finished && afterIntake && allDone && outputEmpty) finished = t;
  }
  r.cycles = *finished + 1;
  r.boxesReceived = intake.boxesReceived;
  played.intakeDone = *intakeDone;
  const auto lc = [&] { const auto l = p.localDims(f.dims); return std::uint64_t{l[0]} * l[1] * l[2]; }();
  for (std::size_t g = 0; g < groups.size(); ++g) {
    if (groups[g].opsDone() != schedules[g].ops.size())
      throw std::logic_error(fmt::format("binning timeline: group {} ran {} of {} schedule cycles", g,
                                         groups[g].opsDone(), schedules[g].ops.size()));
    for (const Op& op : schedules[g].ops) r.issueCycles += !op.bubble;
    played.sortStart.push_back(*intakeDone + 1 + lc);
    played.computeStart.push_back(groups[g].computeAt);
    played.groupDone.push_back(*groups[g].done);
  }
  summarize(binned, played);
  return played;
}

}  // namespace bpaccel::binning
