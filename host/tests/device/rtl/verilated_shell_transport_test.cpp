// The driver over the Verilated shell (BpaccelShell and its core): device
// errors, aborts mid-packet and mid-run, recovery, back-pressure, the
// interrupt path against polling, the counter registers and two clocks.

#include <gtest/gtest.h>

#include <random>

#include "bpaccel_params.h"
#include "bpaccel_shell.h"
#include "device/built_device.hpp"
#include "device/model_backend.hpp"
#include "device/rtl/rtl_backend.hpp"
#include "device/rtl/shell/shell_probe.hpp"
#include "scenes.hpp"

using namespace bpaccel;
using namespace bpaccel::testing;

namespace {

// Timeouts in simulated time (the model's core runs at 250 MHz), short enough that a hang costs little.
ShellDriverConfig quickDriver(bool interrupts = true) {
  return {.interrupts = interrupts, .timeoutFloor = std::chrono::microseconds{20}, .slowestCoreMHz = 50,
          .abortTimeout = std::chrono::microseconds{10}, .readyTimeout = std::chrono::microseconds{10}};
}

struct Shell {
  VerilatedShellTransport transport;
  ShellDriver driver;
  explicit Shell(VerilatedShellConfig shell = {}, ShellDriverConfig config = quickDriver())
      : transport(std::move(shell)), driver(transport, config) {}
  std::uint32_t reg(std::uint32_t offset) { return transport.readRegister(offset); }
  // A 64-bit counter: the low half latches the high half. The counters take
  // a reply two cycles after its TLAST, as STATUS.BUSY falls: wait for that first.
  std::uint64_t counter(std::uint32_t lo) {
    const std::uint64_t limit = transport.counters().busCycles + 1000;
    while (reg(BPACCEL_SHELL_REG_STATUS) & BPACCEL_SHELL_REG_STATUS_BUSY_MASK)
      if (transport.counters().busCycles > limit) throw std::runtime_error("STATUS.BUSY did not fall");
    const std::uint64_t low = reg(lo);
    return low | static_cast<std::uint64_t>(reg(lo + 4)) << 32;
  }
};

// Cells of the adversarial scenes, as keys the device compares.
struct Cells {
  std::vector<std::vector<KeyBox>> keys;
  std::vector<std::span<const KeyBox>> spans;
  Cells(std::size_t count, std::size_t most, unsigned seed) {
    std::mt19937 rng(seed);
    for (std::size_t k = 0; k < count; ++k) {
      auto scenes = adversarialScenes(rng() % (most + 1), static_cast<unsigned>(rng()));
      std::vector<KeyBox> cell;
      toKeys(scenes.at(rng() % scenes.size()).second, cell);
      if constexpr (BPACCEL_KEY_WIDTH < 32) {
        std::vector<KeyBox> narrow(cell.size());
        narrowKeys(cell, BPACCEL_KEY_WIDTH, narrow);
        cell = narrow;
      }
      keys.push_back(std::move(cell));
    }
    for (const auto& c : keys) spans.emplace_back(c);
  }
  CellsCommand command() const { return {spans, {}}; }
};

struct Answer {
  std::vector<Pair> pairs;
  std::vector<std::size_t> ends;
  RunStats stats;
};

Answer modelAnswer(const Cells& cells) {
  ModelBackend model(builtDeviceParams());
  Answer a;
  model.runBatch(cells.spans, a.pairs, a.ends, a.stats);
  return a;
}

Answer shellAnswer(ShellDriver& driver, const Cells& cells) {
  Answer a;
  const Trailer t = driver.runCells(cells.command(), a.pairs, a.ends);
  a.stats = {.runs = t.cells, .batches = 1, .loadCycles = t.intakeCycles, .cycles = t.runCycles(),
             .issueCycles = t.issueCycles, .stallCycles = t.stallCycles, .hits = t.pairs, .boxesSent = t.boxes,
             .beatsReceived = t.records};
  return a;
}

void expectSameAnswer(const Answer& shell, const Answer& model, const std::string& label) {
  EXPECT_EQ(shell.pairs, model.pairs) << label;
  EXPECT_EQ(shell.ends, model.ends) << label;
  EXPECT_EQ(shell.stats.loadCycles, model.stats.loadCycles) << label;
  EXPECT_EQ(shell.stats.cycles, model.stats.cycles) << label;
  EXPECT_EQ(shell.stats.issueCycles, model.stats.issueCycles) << label;
  EXPECT_EQ(shell.stats.beatsReceived, model.stats.beatsReceived) << label;
  EXPECT_EQ(shell.stats.boxesSent, model.stats.boxesSent) << label;
}

// A command's words, by hand: header, cell count, then {count, split} and six keys (or three words) a box.
std::vector<std::uint32_t> packetOf(std::uint32_t header, std::vector<std::uint32_t> body) {
  std::vector<std::uint32_t> words = {header};
  words.insert(words.end(), body.begin(), body.end());
  words.resize((words.size() + BPACCEL_SHELL_WORDS_PER_BEAT - 1) / BPACCEL_SHELL_WORDS_PER_BEAT *
                   BPACCEL_SHELL_WORDS_PER_BEAT,
               0u);
  return words;
}

std::vector<std::uint32_t> boxWords(std::uint32_t at) {
  if (BPACCEL_SHELL_BOX_WORDS == 6) return {at, at, at, at + 1, at + 1, at + 1};
  return {at | at << 16, at | (at + 1) << 16, (at + 1) | (at + 1) << 16};
}

std::vector<std::uint32_t> concat(std::initializer_list<std::vector<std::uint32_t>> parts) {
  std::vector<std::uint32_t> out;
  for (const auto& p : parts) out.insert(out.end(), p.begin(), p.end());
  return out;
}

constexpr std::uint32_t kCells = BPACCEL_SHELL_OP_CELLS | BPACCEL_SHELL_PROTOCOL_VERSION << 8;

// A transport between the driver and the Verilated shell that raises the
// count of the first cell of the next packet above the capacity, after the
// driver's own checks: the device, not the host, finds the error.
class CountCorruptingTransport final : public ShellTransport {
 public:
  explicit CountCorruptingTransport(ShellTransport& inner) : inner_(inner) {}
  bool corruptNext = false;

  std::uint32_t readRegister(std::uint32_t offset) override { return inner_.readRegister(offset); }
  void writeRegister(std::uint32_t offset, std::uint32_t value) override { inner_.writeRegister(offset, value); }
  void postReceive(std::size_t maxWords) override { inner_.postReceive(maxWords); }
  void send(std::span<const std::uint32_t> packet) override {
    std::vector<std::uint32_t> words(packet.begin(), packet.end());
    if (corruptNext) words.at(2) = BPACCEL_CAPACITY + 1;  // header, cell count, then cell 0's count
    corruptNext = false;
    inner_.send(words);
  }
  bool receive(std::vector<std::uint32_t>& reply, std::chrono::microseconds timeout) override {
    return inner_.receive(reply, timeout);
  }
  bool waitInterrupt(std::chrono::microseconds timeout) override { return inner_.waitInterrupt(timeout); }
  void resetChannels() override { inner_.resetChannels(); }
  std::chrono::nanoseconds now() override { return inner_.now(); }

 private:
  ShellTransport& inner_;
};

}  // namespace

TEST(VerilatedShell, ADeviceErrorThrowsNamingItsCodeAndTheNextCommandIsExact) {
  VerilatedShellTransport verilated;
  CountCorruptingTransport transport(verilated);
  ShellDriver driver(transport, quickDriver());
  const Cells cells(3, 30, 14);
  std::vector<Pair> out = {{7, 9}};
  std::vector<std::size_t> ends = {1};
  transport.corruptNext = true;
  try {
    driver.runCells(cells.command(), out, ends);
    ADD_FAILURE() << "a device error was not reported";
  } catch (const ShellDeviceError& e) {
    EXPECT_EQ(shellErrorName(e.code()), "COUNT_OVER_CAPACITY");
    EXPECT_EQ(e.detail(), 0u);  // the cell
    EXPECT_NE(std::string(e.what()).find("COUNT_OVER_CAPACITY"), std::string::npos) << e.what();
  }
  EXPECT_EQ(out, (std::vector<Pair>{{7, 9}}));  // nothing of the failed command kept
  EXPECT_EQ(ends, (std::vector<std::size_t>{1}));
  EXPECT_EQ(driver.events().recoveries, 0u);  // the error reply kept the streams in step
  expectSameAnswer(shellAnswer(driver, cells), modelAnswer(cells), "after the device error");
}

TEST(VerilatedShell, DeviceErrorsComeBackAsTrailersNamingTheCellAndTheStreamStaysInStep) {
  Shell shell;
  const auto box = boxWords(3);
  const std::uint32_t splitError = BPACCEL_BIPARTITE_RUNS ? BPACCEL_SHELL_ERR_SPLIT_OUT_OF_RANGE
                                                          : BPACCEL_SHELL_ERR_SPLIT_UNSUPPORTED;
  const std::uint32_t badSplit = BPACCEL_BIPARTITE_RUNS ? 2u : 1u;  // not below 2 boxes; any on the seed
  struct Case {
    const char* what;
    std::vector<std::uint32_t> packet;
    std::uint32_t error, detail;
  };
  const std::vector<Case> cases = {
      {"a count above the capacity", packetOf(kCells, concat({{2, 1, 0}, box, {BPACCEL_CAPACITY + 1, 0}})),
       BPACCEL_SHELL_ERR_COUNT_OVER_CAPACITY, 1},
      {"a bad split", packetOf(kCells, concat({{3, 0, 0, 2, badSplit}, box, box})), splitError, 1},
      {"a packet that ends inside a cell", packetOf(kCells, concat({{1, 3, 0}, box, box})),
       BPACCEL_SHELL_ERR_LENGTH_MISMATCH, 0},
      {"FRAME on a CELLS device", packetOf(BPACCEL_SHELL_OP_FRAME | 1 << 8, concat({{1, 0, 0x010101}, box})),
       BPACCEL_SHELL_ERR_BAD_COMMAND, 0},
      {"another protocol version", packetOf(BPACCEL_SHELL_OP_CELLS | 2 << 8, {0}), BPACCEL_SHELL_ERR_BAD_COMMAND, 0},
  };
  std::vector<std::uint32_t> reply;
  for (const Case& c : cases) {
    const Trailer t = shell.driver.exchange(c.packet, 1024, std::chrono::microseconds{20}, reply);
    EXPECT_EQ(shellErrorName(t.error), shellErrorName(c.error)) << c.what;
    EXPECT_EQ(t.detail, c.detail) << c.what;
    EXPECT_EQ(shell.driver.events().lastIrqStatus,
              BPACCEL_SHELL_REG_IRQ_STATUS_REPLY_MASK | BPACCEL_SHELL_REG_IRQ_STATUS_ERROR_MASK)
        << c.what;
    EXPECT_EQ(shell.reg(BPACCEL_SHELL_REG_LAST_DETAIL), c.detail) << c.what;
  }
  // Every error was drained to its TLAST: the next command is answered exactly.
  const Cells cells(5, 40, 1);
  expectSameAnswer(shellAnswer(shell.driver, cells), modelAnswer(cells), "after the errors");
  EXPECT_EQ(shell.counter(BPACCEL_SHELL_REG_REPLIES_LO), cases.size() + 1);
  EXPECT_EQ(shell.counter(BPACCEL_SHELL_REG_ERRORS_LO), cases.size());
  EXPECT_EQ(shell.driver.events().recoveries, 0u);
  EXPECT_EQ(shell.driver.events().timeouts, 0u);
}

TEST(VerilatedShell, AbortMidPacketRepliesAtOnceAndTheRestOfThePacketIsDrained) {
  // The send channel stops after a few beats of the packet, as a stuck DMA would.
  bool stuck = true;
  std::uint64_t beats = 0;
  Shell shell({.sendReady = [&](std::uint64_t) { return !stuck || beats++ < 5; }}, quickDriver(false));
  const Cells cells(4, 60, 2);
  std::vector<std::uint32_t> packet;
  encodeCells(shell.driver.format(), cells.command(), packet);
  ASSERT_GT(packet.size(), 6u * BPACCEL_SHELL_WORDS_PER_BEAT);
  std::vector<std::uint32_t> reply;
  shell.transport.postReceive(cellsReplyWords(shell.driver.format(), cells.command()));
  shell.transport.send(packet);
  EXPECT_FALSE(shell.transport.receive(reply, std::chrono::microseconds{5}));  // the packet never ends
  EXPECT_NE(shell.reg(BPACCEL_SHELL_REG_STATUS) & BPACCEL_SHELL_REG_STATUS_IN_PACKET_MASK, 0u);
  shell.transport.writeRegister(BPACCEL_SHELL_REG_CONTROL, BPACCEL_SHELL_REG_CONTROL_ABORT_MASK);
  ASSERT_TRUE(shell.transport.receive(reply, std::chrono::microseconds{5}));  // without waiting for the packet
  EXPECT_EQ(shellErrorName(decodeTrailer(shell.driver.format(), reply).error), "ABORTED");
  stuck = false;  // the rest of the packet comes and is dropped
  while (shell.reg(BPACCEL_SHELL_REG_STATUS) & (BPACCEL_SHELL_REG_STATUS_IN_PACKET_MASK | BPACCEL_SHELL_REG_STATUS_BUSY_MASK))
    ASSERT_LT(shell.transport.counters().busCycles, 100000u);
  expectSameAnswer(shellAnswer(shell.driver, cells), modelAnswer(cells), "after the abort");
  EXPECT_EQ(shell.counter(BPACCEL_SHELL_REG_REPLIES_LO), 2u);  // no soft reset restarted the counters
}

TEST(VerilatedShell, ATimeoutMidPacketAbortsThenResetsTheShellWhoseInputStaysOpen) {
  bool stuck = true;
  std::uint64_t beats = 0;
  Shell shell({.sendReady = [&](std::uint64_t) { return !stuck || beats++ < 5; }});
  const Cells cells(4, 60, 3);
  std::vector<Pair> out;
  std::vector<std::size_t> ends;
  try {
    shell.driver.runCells(cells.command(), out, ends);
    ADD_FAILURE() << "a stuck send was not reported";
  } catch (const ShellTimeout& e) {
    EXPECT_NE(std::string(e.what()).find("reset the shell"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(out.empty());
  EXPECT_EQ(shell.driver.events().aborts, 1u);
  EXPECT_EQ(shell.driver.events().recoveries, 1u);
  EXPECT_EQ(shell.transport.counters().channelResets, 1u);
  stuck = false;
  expectSameAnswer(shellAnswer(shell.driver, cells), modelAnswer(cells), "after the reset");
  EXPECT_EQ(shell.counter(BPACCEL_SHELL_REG_REPLIES_LO), 1u);  // the soft reset restarted the counters
  EXPECT_FALSE(shell.transport.interruptLine());
}

TEST(VerilatedShell, ATimeoutDuringALongRunAbortsWithoutAReset) {
  // One full cell of overlapping boxes: a run far longer than the timeout's 20 us (5,000 bus cycles).
  ShellDriverConfig config = quickDriver();
  config.timeoutMargin = 0;
  Shell shell({}, config);
  std::vector<KeyBox> full(BPACCEL_CAPACITY, KeyBox{{1, 1, 1}, {2, 2, 2}});
  const std::vector<std::span<const KeyBox>> one = {full};
  ASSERT_GT(scheduleIssueCycles(full.size(), BPACCEL_M), 20000u);
  std::vector<Pair> out;
  std::vector<std::size_t> ends;
  EXPECT_THROW(shell.driver.runCells({one, {}}, out, ends), ShellTimeout);
  EXPECT_TRUE(out.empty());
  EXPECT_EQ(shell.driver.events().aborts, 1u);
  EXPECT_EQ(shell.driver.events().recoveries, 0u);  // the whole packet was in: the abort was enough
  EXPECT_EQ(shellErrorName((shell.reg(BPACCEL_SHELL_REG_LAST_REPLY) & BPACCEL_SHELL_REG_LAST_REPLY_ERROR_MASK) >>
                           BPACCEL_SHELL_REG_LAST_REPLY_ERROR_SHIFT),
            "ABORTED");
  const Cells cells(3, 30, 4);
  expectSameAnswer(shellAnswer(shell.driver, cells), modelAnswer(cells), "after the abort");
  EXPECT_EQ(shell.counter(BPACCEL_SHELL_REG_REPLIES_LO), 2u);
}

TEST(VerilatedShell, AReplyLongerThanItsBufferIsReportedAndTheShellReset) {
  Shell shell;
  std::vector<KeyBox> cluster(40, KeyBox{{1, 1, 1}, {2, 2, 2}});
  const std::vector<std::span<const KeyBox>> one = {cluster};
  std::vector<std::uint32_t> packet, reply;
  encodeCells(shell.driver.format(), {one, {}}, packet);
  try {
    shell.driver.exchange(packet, 2 * BPACCEL_SHELL_TRAILER_WORDS, std::chrono::microseconds{20}, reply);
    ADD_FAILURE() << "a cut reply was taken";
  } catch (const ShellProtocolError& e) {
    EXPECT_NE(std::string(e.what()).find("it was longer"), std::string::npos) << e.what();
  }
  EXPECT_EQ(shell.driver.events().recoveries, 1u);
  const Cells cells(3, 30, 6);
  expectSameAnswer(shellAnswer(shell.driver, cells), modelAnswer(cells), "after the reset");
}

TEST(VerilatedShell, ASlowSendChannelStarvesTheCoreButLosesNothing) {
  std::mt19937 pattern(7);
  Shell shell({.sendReady = [&](std::uint64_t) { return pattern() % 2 == 0; }});
  const Cells cells(BPACCEL_BATCH_CELLS, 50, 8);
  const Answer got = shellAnswer(shell.driver, cells), expected = modelAnswer(cells);
  EXPECT_EQ(got.pairs, expected.pairs);
  EXPECT_EQ(got.ends, expected.ends);
  EXPECT_EQ(got.stats.issueCycles, expected.stats.issueCycles);
  EXPECT_GT(got.stats.loadCycles, expected.stats.loadCycles);  // the core waited for boxes
}

TEST(VerilatedShell, InterruptsAndPollingGiveTheSameAnswersAndOnlyInterruptsRaiseTheLine) {
  const Cells cells(2 * BPACCEL_BATCH_CELLS + 3, 40, 9);
  std::vector<Answer> answers;
  for (bool interrupts : {true, false}) {
    RtlBackend rtl(RtlBackendConfig{.driver = quickDriver(interrupts)});
    Answer a;
    rtl.runBatch(cells.spans, a.pairs, a.ends, a.stats);
    answers.push_back(a);
    const std::uint64_t commands = rtl.driver().events().commands;
    EXPECT_EQ(commands, 3u);
    const std::uint32_t causes = rtl.transport().readRegister(BPACCEL_SHELL_REG_IRQ_STATUS);
    if (interrupts) {
      EXPECT_EQ(rtl.driver().events().interrupts, commands);
      EXPECT_EQ(rtl.transport().counters().interruptRises, commands);  // one rise a reply: each acknowledged
      EXPECT_EQ(causes, 0u);
    } else {
      EXPECT_EQ(rtl.driver().events().interrupts, 0u);
      EXPECT_EQ(rtl.transport().counters().interruptRises, 0u);
      EXPECT_EQ(causes, BPACCEL_SHELL_REG_IRQ_STATUS_REPLY_MASK);  // set, never acknowledged
    }
    EXPECT_FALSE(rtl.transport().interruptLine());
  }
  EXPECT_EQ(answers[0].pairs, answers[1].pairs);
  EXPECT_EQ(answers[0].ends, answers[1].ends);
  EXPECT_EQ(answers[0].stats.deviceCycles(), answers[1].stats.deviceCycles());
  const Answer model = [&] {
    Answer m;
    ModelBackend(builtDeviceParams()).runBatch(cells.spans, m.pairs, m.ends, m.stats);
    return m;
  }();
  EXPECT_EQ(answers[0].pairs, model.pairs);
  EXPECT_EQ(answers[0].stats.deviceCycles(), model.stats.deviceCycles());
}

TEST(VerilatedShell, TheCounterRegistersSumTheTrailers) {
  Shell shell;
  Answer sum;
  for (unsigned seed : {10u, 11u, 12u}) {
    const Answer a = shellAnswer(shell.driver, Cells(6, 50, seed));
    sum.stats += a.stats;
  }
  EXPECT_EQ(shell.counter(BPACCEL_SHELL_REG_REPLIES_LO), 3u);
  EXPECT_EQ(shell.counter(BPACCEL_SHELL_REG_ERRORS_LO), 0u);
  EXPECT_EQ(shell.counter(BPACCEL_SHELL_REG_RECORDS_LO), sum.stats.beatsReceived);
  EXPECT_EQ(shell.counter(BPACCEL_SHELL_REG_BOXES_LO), sum.stats.boxesSent);
  EXPECT_EQ(shell.counter(BPACCEL_SHELL_REG_DEVICE_CYCLES_LO), sum.stats.deviceCycles());
  EXPECT_EQ(shell.counter(BPACCEL_SHELL_REG_INTAKE_CYCLES_LO), sum.stats.loadCycles);
  EXPECT_EQ(shell.counter(BPACCEL_SHELL_REG_ISSUE_CYCLES_LO), sum.stats.issueCycles);
  EXPECT_EQ(shell.counter(BPACCEL_SHELL_REG_STALL_CYCLES_LO), 0u);
  EXPECT_EQ(shell.counter(BPACCEL_SHELL_REG_PAIRS_LO), sum.stats.hits);
  EXPECT_GT(shell.counter(BPACCEL_SHELL_REG_BUSY_CYCLES_LO), sum.stats.deviceCycles() / 2);
}

TEST(VerilatedShell, TwoClocksGiveTheModelsCyclesWhenTheBusKeepsUpAndExactPairsWhenItCannot) {
  if (!BPACCEL_SHELL_DUAL_CLOCK) GTEST_SKIP() << "this shell has one clock";
  const Cells cells(BPACCEL_BATCH_CELLS, 50, 13);
  const Answer model = modelAnswer(cells);
  {
    Shell slowCore({.busPeriodPs = 4000, .corePeriodPs = 6000});  // 250 MHz bus, 167 MHz core
    expectSameAnswer(shellAnswer(slowCore.driver, cells), model, "core slower than the bus");
  }
  Shell fastCore({.busPeriodPs = 4000, .corePeriodPs = 1500});  // the bus brings a box every 2 core cycles or so
  const Answer got = shellAnswer(fastCore.driver, cells);
  EXPECT_EQ(got.pairs, model.pairs);
  EXPECT_EQ(got.ends, model.ends);
  EXPECT_EQ(got.stats.issueCycles, model.stats.issueCycles);
  EXPECT_GT(got.stats.loadCycles, model.stats.loadCycles);
}
