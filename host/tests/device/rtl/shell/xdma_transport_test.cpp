// XdmaTransport on regular files standing in for XDMA's character devices:
// what it reads and writes where, not the DMA engine (untested on a card).

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

#include <unistd.h>

#include "device/rtl/shell/xdma_transport.hpp"

using namespace bpaccel;

namespace {

// Four files in a fresh folder: a 4 KiB BAR, the two channels and the events file.
struct FakeDevices {
  std::filesystem::path dir;
  XdmaPaths paths;
  FakeDevices() {
    dir = std::filesystem::temp_directory_path() / ("xdma-test-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    paths = {.user = (dir / "user").string(), .h2c = (dir / "h2c").string(), .c2h = (dir / "c2h").string(),
             .events = (dir / "events").string(), .registerBase = 0x1000};
    write("user", std::string(0x2000, '\0'));
    write("h2c", "");
    write("events", std::string("\x01\x00\x00\x00", 4));
  }
  ~FakeDevices() { std::filesystem::remove_all(dir); }
  void write(const std::string& name, const std::string& bytes) const {
    std::ofstream(dir / name, std::ios::binary | std::ios::trunc) << bytes;
  }
  std::string read(const std::string& name) const {
    std::ifstream in(dir / name, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), {}};
  }
};

}  // namespace

TEST(XdmaTransport, RegistersAreLittleEndianWordsAtTheirOffsetInTheBar) {
  FakeDevices devices;
  devices.write("c2h", "");
  XdmaTransport xdma(devices.paths);
  xdma.writeRegister(0x114, 0x04030201u);
  EXPECT_EQ(devices.read("user").substr(0x1114, 4), std::string("\x01\x02\x03\x04", 4));
  EXPECT_EQ(xdma.readRegister(0x114), 0x04030201u);
  EXPECT_EQ(xdma.readRegister(0x110), 0u);
}

TEST(XdmaTransport, SendsThePacketsBytesAndReceivesTheReplysWords) {
  FakeDevices devices;
  devices.write("c2h", std::string("\x0a\x00\x00\x00\x0b\x00\x00\xb7", 8));
  XdmaTransport xdma(devices.paths);
  xdma.postReceive(16);
  const std::vector<std::uint32_t> packet = {0x0102, 2, 0xdeadbeef, 0};
  xdma.send(packet);
  std::vector<std::uint32_t> reply;
  ASSERT_TRUE(xdma.receive(reply, std::chrono::seconds{5}));
  EXPECT_EQ(reply, (std::vector<std::uint32_t>{0x0a, 0xb700000bu}));
  EXPECT_FALSE(xdma.receive(reply, std::chrono::microseconds{1}));  // nothing more posted
  xdma.resetChannels();  // the send has ended
  EXPECT_EQ(devices.read("h2c"), std::string("\x02\x01\x00\x00\x02\x00\x00\x00\xef\xbe\xad\xde\x00\x00\x00\x00", 16));
  EXPECT_TRUE(xdma.waitInterrupt(std::chrono::milliseconds{100}));  // a regular file polls readable
}

TEST(XdmaTransport, AMissingDeviceIsNamed) {
  FakeDevices devices;
  devices.write("c2h", "");
  XdmaPaths paths = devices.paths;
  paths.h2c = (devices.dir / "absent").string();
  try {
    XdmaTransport xdma(paths);
    ADD_FAILURE() << "opened a missing device";
  } catch (const std::system_error& e) {
    EXPECT_NE(std::string(e.what()).find("absent"), std::string::npos) << e.what();
  }
}
