// ShellDriver against a fake transport: the register sequence of the probe
// and of each command, error trailers, timeouts, aborts and recovery
// (docs/integration.md, "One frame, as the driver does it").

#include <gtest/gtest.h>

#include <algorithm>

#include "device/rtl/shell/shell_driver.hpp"
#include "fake_shell_transport.hpp"

using namespace bpaccel;
using namespace bpaccel::testing;

namespace {

constexpr std::uint32_t kIrqBoth = BPACCEL_SHELL_REG_IRQ_STATUS_REPLY_MASK | BPACCEL_SHELL_REG_IRQ_STATUS_ERROR_MASK;

KeyBox unitBox(std::uint32_t at) { return {{at, at, at}, {at + 1, at + 1, at + 1}}; }

// Two cells with overlaps: a chain (i overlaps i + 1) and a cluster.
struct TwoCells {
  std::vector<KeyBox> chain, cluster;
  std::vector<std::span<const KeyBox>> spans;
  TwoCells() {
    for (std::uint32_t i = 0; i < 12; ++i) chain.push_back(unitBox(i));
    cluster.assign(5, unitBox(7));
    spans = {chain, cluster};
  }
  CellsCommand command() const { return {spans, {}}; }
};

// The index in the log of the first entry equal to `entry` at or after `from`; log size if none.
std::size_t find(const FakeShellTransport& t, const std::string& entry, std::size_t from = 0) {
  return static_cast<std::size_t>(std::find(t.log.begin() + static_cast<std::ptrdiff_t>(from), t.log.end(), entry) -
                                  t.log.begin());
}

ShellDriverConfig quick(bool interrupts = true) {
  return {.interrupts = interrupts, .timeoutFloor = std::chrono::microseconds{50}, .timeoutMargin = 0,
          .abortTimeout = std::chrono::microseconds{20}, .readyTimeout = std::chrono::microseconds{20}};
}

std::string probeFailure(FakeShellTransport& t) {
  try {
    ShellDriver driver(t);
  } catch (const ShellProbeError& e) {
    return e.what();
  }
  return "probed";
}

}  // namespace

TEST(ShellDriverProbe, ChecksIdentityAndCapabilitiesThenClearsAndEnablesInterrupts) {
  for (bool interrupts : {true, false}) {
    FakeShellTransport t;
    ShellDriver driver(t, quick(interrupts));
    EXPECT_EQ(t.log.front(), readOf(BPACCEL_SHELL_REG_ID));
    for (const ExpectedRegister& r : builtShellIdentity().capabilities) EXPECT_LT(find(t, readOf(r.offset)), t.log.size()) << r.name;
    const std::size_t clear = find(t, writeOf(BPACCEL_SHELL_REG_IRQ_STATUS, kIrqBoth));
    const std::size_t enable = find(t, writeOf(BPACCEL_SHELL_REG_IRQ_ENABLE, interrupts ? kIrqBoth : 0u));
    EXPECT_LT(clear, enable);  // stale causes cleared before the line is enabled
    EXPECT_LT(enable, t.log.size());
    EXPECT_EQ(t.log.back(), readOf(BPACCEL_SHELL_REG_STATUS));  // READY
    EXPECT_EQ(t.count("reset channels"), 0u);
  }
}

TEST(ShellDriverProbe, NamesTheFirstRegisterThatDiffersFromTheBuiltShell) {
  FakeShellTransport noShell;
  noShell.regs[BPACCEL_SHELL_REG_ID] = 0xFFFFFFFF;  // nothing at the BAR
  EXPECT_NE(probeFailure(noShell).find("no bpaccel shell answers: ID reads 0xffffffff"), std::string::npos);
  FakeShellTransport protocol;
  protocol.regs[BPACCEL_SHELL_REG_VERSION] += 1;
  EXPECT_NE(probeFailure(protocol).find("VERSION.PROTOCOL"), std::string::npos);
  FakeShellTransport lanes;
  lanes.regs[BPACCEL_SHELL_REG_LANES] = BPACCEL_SHELL_REG_LANES_RESET * 2;
  lanes.regs[BPACCEL_SHELL_REG_FINGERPRINT] ^= 1;
  const std::string message = probeFailure(lanes);
  EXPECT_NE(message.find(fmt::format("LANES is {:#x} but this host was built for {:#x}", BPACCEL_SHELL_REG_LANES_RESET * 2,
                                     BPACCEL_SHELL_REG_LANES_RESET)),
            std::string::npos)
      << message;
  EXPECT_NE(message.find(BPACCEL_SHELL_FINGERPRINT_TEXT), std::string::npos) << message;
  FakeShellTransport fifo;  // only the fingerprint differs
  fifo.regs[BPACCEL_SHELL_REG_FINGERPRINT] ^= 1;
  EXPECT_NE(probeFailure(fifo).find("every capability register agrees"), std::string::npos);
  FakeShellTransport same;
  EXPECT_EQ(probeFailure(same), "probed");
}

TEST(ShellDriverProbe, RecoversAShellLeftInsideACommand) {
  FakeShellTransport t;
  t.regs[BPACCEL_SHELL_REG_STATUS] |= BPACCEL_SHELL_REG_STATUS_IN_PACKET_MASK;  // a process died mid-frame
  ShellDriver driver(t, quick());
  const std::size_t reset = find(t, "reset channels");
  const std::size_t soft = find(t, writeOf(BPACCEL_SHELL_REG_CONTROL, BPACCEL_SHELL_REG_CONTROL_SOFT_RESET_MASK));
  EXPECT_LT(reset, soft);  // the DMA is halted before the shell drops what the streams hold
  EXPECT_LT(soft, t.log.size());
  EXPECT_EQ(driver.events().recoveries, 1u);
  EXPECT_GE(t.count(readOf(BPACCEL_SHELL_REG_STATUS)), 1u + 2u + 1u);  // the check, READY low twice, READY
}

TEST(ShellDriverCommand, PostsTheReceiveSendsWaitsAcknowledgesAndDecodes) {
  FakeShellTransport t;
  ShellDriver driver(t, quick());
  const TwoCells cells;
  const std::size_t start = t.log.size();
  std::vector<Pair> out;
  std::vector<std::size_t> ends;
  const Trailer trailer = driver.runCells(cells.command(), out, ends);
  const std::vector<std::string> expected = {
      fmt::format("post {}", cellsReplyWords(driver.format(), cells.command())),
      fmt::format("send {}", t.sent.back().size()),
      "wait interrupt",
      readOf(BPACCEL_SHELL_REG_IRQ_STATUS),
      writeOf(BPACCEL_SHELL_REG_IRQ_STATUS, BPACCEL_SHELL_REG_IRQ_STATUS_REPLY_MASK),
      "receive"};
  EXPECT_EQ(std::vector<std::string>(t.log.begin() + static_cast<std::ptrdiff_t>(start), t.log.end()), expected);
  // The chain's 11 neighbours, the cluster's 10 pairs, cell by cell.
  ASSERT_EQ(ends, (std::vector<std::size_t>{11, 21}));
  for (std::uint32_t i = 0; i < 11; ++i) EXPECT_EQ(std::count(out.begin(), out.begin() + 11, Pair{i, i + 1}), 1);
  EXPECT_EQ(trailer.pairs, 21u);
  EXPECT_EQ(trailer.boxes, 17u);
  EXPECT_EQ(driver.events().interrupts, 1u);
  EXPECT_EQ(driver.events().lastIrqStatus, BPACCEL_SHELL_REG_IRQ_STATUS_REPLY_MASK);
}

TEST(ShellDriverCommand, PollingWaitsForTheReceiveAloneAndNeverTouchesTheInterrupt) {
  FakeShellTransport t;
  ShellDriver driver(t, quick(false));
  const TwoCells cells;
  const std::size_t start = t.log.size();
  std::vector<Pair> out;
  std::vector<std::size_t> ends;
  driver.runCells(cells.command(), out, ends);
  EXPECT_EQ(std::vector<std::string>(t.log.begin() + static_cast<std::ptrdiff_t>(start), t.log.end()),
            (std::vector<std::string>{fmt::format("post {}", cellsReplyWords(driver.format(), cells.command())),
                                      fmt::format("send {}", t.sent.back().size()), "receive"}));
  EXPECT_EQ(out.size(), 21u);
  EXPECT_EQ(driver.events().interrupts, 0u);
}

TEST(ShellDriverCommand, AnErrorTrailerThrowsItsNameAndDetailAndKeepsNothing) {
  FakeShellTransport t;
  t.answer = [](const std::vector<std::uint32_t>& packet) {
    ReferenceTrailer trailer{.error = BPACCEL_SHELL_ERR_COUNT_OVER_CAPACITY, .detail = 1};
    auto reply = referenceCellsReply(builtShellIdentity().format, packet);  // records sent before the error was found
    const auto end = trailerWords(trailer);
    std::copy(end.begin(), end.end(), reply.end() - 16);
    return reply;
  };
  ShellDriver driver(t, quick());
  const TwoCells cells;
  std::vector<Pair> out = {{0, 1}};
  std::vector<std::size_t> ends = {1};
  try {
    driver.runCells(cells.command(), out, ends);
    ADD_FAILURE() << "an error trailer was taken for an answer";
  } catch (const ShellDeviceError& e) {
    EXPECT_EQ(e.code(), static_cast<std::uint32_t>(BPACCEL_SHELL_ERR_COUNT_OVER_CAPACITY));
    EXPECT_EQ(e.detail(), 1u);
    EXPECT_NE(std::string(e.what()).find("COUNT_OVER_CAPACITY (error code 1, detail 1)"), std::string::npos) << e.what();
  }
  EXPECT_EQ(out.size(), 1u);
  EXPECT_EQ(ends.size(), 1u);
  EXPECT_EQ(driver.events().lastIrqStatus, kIrqBoth);  // REPLY and ERROR
  EXPECT_EQ(driver.events().recoveries, 0u);  // an error trailer leaves the stream in step
}

TEST(ShellDriverTimeout, AbortsAndTheAbortedReplyKeepsTheStreamInStep) {
  FakeShellTransport t;
  ShellDriver driver(t, quick());
  t.silentCommands = 1;
  const TwoCells cells;
  std::vector<Pair> out;
  std::vector<std::size_t> ends;
  EXPECT_THROW(driver.runCells(cells.command(), out, ends), ShellTimeout);
  EXPECT_TRUE(out.empty());
  EXPECT_EQ(t.count(writeOf(BPACCEL_SHELL_REG_CONTROL, BPACCEL_SHELL_REG_CONTROL_ABORT_MASK)), 1u);
  EXPECT_EQ(t.count("reset channels"), 0u);
  EXPECT_EQ(driver.events().aborts, 1u);
  EXPECT_EQ(driver.events().recoveries, 0u);
  EXPECT_EQ(t.regs[BPACCEL_SHELL_REG_IRQ_STATUS], 0u);  // the ABORTED reply's interrupt acknowledged
  driver.runCells(cells.command(), out, ends);  // the next command is whole
  EXPECT_EQ(out.size(), 21u);
}

TEST(ShellDriverTimeout, RecoversWhenTheAbortGetsNoReplyOrLeavesThePacketOpen) {
  for (bool answersAbort : {false, true}) {
    FakeShellTransport t;
    ShellDriver driver(t, quick());
    t.silentCommands = 1;
    t.answersAbort = answersAbort;
    t.abortLeavesInPacket = true;  // the DMA still owes the packet's rest
    const TwoCells cells;
    std::vector<Pair> out;
    std::vector<std::size_t> ends;
    try {
      driver.runCells(cells.command(), out, ends);
      ADD_FAILURE() << "a hang was not reported";
    } catch (const ShellTimeout& e) {
      EXPECT_NE(std::string(e.what()).find("reset the shell"), std::string::npos) << e.what();
    }
    const std::size_t abort = find(t, writeOf(BPACCEL_SHELL_REG_CONTROL, BPACCEL_SHELL_REG_CONTROL_ABORT_MASK));
    const std::size_t reset = find(t, "reset channels", abort);
    const std::size_t soft = find(t, writeOf(BPACCEL_SHELL_REG_CONTROL, BPACCEL_SHELL_REG_CONTROL_SOFT_RESET_MASK));
    EXPECT_LT(abort, reset);
    EXPECT_LT(reset, soft);
    EXPECT_LT(soft, find(t, writeOf(BPACCEL_SHELL_REG_IRQ_STATUS, kIrqBoth), soft));  // causes cleared after
    EXPECT_EQ(driver.events().recoveries, 1u);
    driver.runCells(cells.command(), out, ends);
    EXPECT_EQ(out.size(), 21u) << answersAbort;
  }
}

TEST(ShellDriverTimeout, AShellThatNeverComesBackReadyIsAnError) {
  FakeShellTransport t;
  ShellDriver driver(t, quick());
  t.silentCommands = 1;
  t.answersAbort = false;
  t.readyAfterReads = 1000000;
  const TwoCells cells;
  std::vector<Pair> out;
  std::vector<std::size_t> ends;
  EXPECT_THROW(driver.runCells(cells.command(), out, ends), ShellProtocolError);
}

TEST(ShellDriverReply, ABrokenReplyRecoversTheShellAndSaysWhy) {
  FakeShellTransport t;
  ShellDriver driver(t, quick());
  const TwoCells cells;
  std::vector<Pair> out;
  std::vector<std::size_t> ends;
  t.answer = [](const std::vector<std::uint32_t>& packet) {  // a reply to another command
    auto reply = referenceCellsReply(builtShellIdentity().format, packet);
    reply[reply.size() - 16] ^= 0x3u << 16;
    return reply;
  };
  EXPECT_THROW(driver.runCells(cells.command(), out, ends), ShellProtocolError);
  EXPECT_EQ(driver.events().recoveries, 1u);
  t.answer = [](const std::vector<std::uint32_t>& packet) {  // more records than the posted buffer holds
    auto reply = referenceCellsReply(builtShellIdentity().format, packet);
    reply.insert(reply.begin(), 64 * BPACCEL_SHELL_WORDS_PER_BEAT, 0u);
    return reply;
  };
  try {
    driver.runCells(cells.command(), out, ends);
    ADD_FAILURE() << "a cut reply was taken";
  } catch (const ShellProtocolError& e) {
    EXPECT_NE(std::string(e.what()).find("it was longer"), std::string::npos) << e.what();
  }
  EXPECT_EQ(driver.events().recoveries, 2u);
  EXPECT_TRUE(out.empty());
}

TEST(ShellDriverFrame, EncodesSendsAndDecodesAFrameThroughTheSameSequence) {
  FakeShellTransport t;
  ShellDriver driver(t, quick());
  const std::vector<KeyBox> boxes = {unitBox(0), unitBox(1), unitBox(5)};
  t.answer = [&](const std::vector<std::uint32_t>& packet) {
    EXPECT_EQ(packet[0], 0x0101u);
    const ShellFormat f = builtShellIdentity().format;
    return packReply(f, {indexWords(f, 0, 1)}, {.opcode = BPACCEL_SHELL_OP_FRAME, .records = 1, .boxes = 3,
                                                .pairs = 1});
  };
  std::vector<Pair> out;
  if (driver.format().cellBits == 0) {  // a CELLS device: the encoder refuses before the device sees it
    EXPECT_THROW(driver.runFrame(boxes, {}, 8, out), std::invalid_argument);
    EXPECT_TRUE(t.sent.empty());
    return;
  }
  driver.runFrame(boxes, {.shift = 4, .cells = {1, 1, 1}}, 8, out);
  EXPECT_EQ(out, (std::vector<Pair>{{0, 1}}));
}

TEST(ShellReply, NamesEveryErrorCodeTheGeneratedHeaderDefines) {
  // The FRAME device's codes too; an unknown code is named by its number.
  EXPECT_EQ(shellErrorName(BPACCEL_SHELL_ERR_GROUP_OVERFLOW), "GROUP_OVERFLOW");
  EXPECT_EQ(shellErrorName(BPACCEL_SHELL_ERR_BAD_GRID), "BAD_GRID");
  EXPECT_EQ(shellErrorName(BPACCEL_SHELL_ERR_BOX_INVERTED), "BOX_INVERTED");
  EXPECT_EQ(shellErrorName(250), "error 250");
}
