#include "xdma_transport.hpp"

#include <fcntl.h>
#include <poll.h>
#include <unistd.h>

#include <cerrno>
#include <system_error>

#include <fmt/format.h>

namespace bpaccel {
namespace {

[[noreturn]] void fail(const std::string& what) { throw std::system_error(errno, std::generic_category(), what); }

// Every byte of `bytes` through `fd`, or an error naming `path`.
void writeAll(int fd, const std::vector<std::uint32_t>& words, const std::string& path) {
  const auto* at = reinterpret_cast<const char*>(words.data());
  std::size_t left = words.size() * 4;
  while (left > 0) {
    const ssize_t n = ::write(fd, at, left);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) fail(fmt::format("xdma: write of {} bytes to {}", left, path));
    at += n;
    left -= static_cast<std::size_t>(n);
  }
}

}  // namespace

FileDescriptor::FileDescriptor(const std::string& path, int flags) : fd_(::open(path.c_str(), flags | O_CLOEXEC)) {
  if (fd_ < 0) fail("xdma: open " + path);
}

FileDescriptor::~FileDescriptor() { ::close(fd_); }

XdmaTransport::XdmaTransport(XdmaPaths paths)
    : paths_(std::move(paths)),
      user_(paths_.user, O_RDWR),
      h2c_(paths_.h2c, O_WRONLY),
      c2h_(paths_.c2h, O_RDONLY),
      events_(paths_.events, O_RDONLY) {}

XdmaTransport::~XdmaTransport() {
  try {
    resetChannels();
  } catch (...) {  // a transfer's error has nobody left to take it
  }
}

std::uint32_t XdmaTransport::readRegister(std::uint32_t offset) {
  std::uint32_t value = 0;  // the BAR is little endian, as the host (x86, arm64) is
  if (::pread(user_.get(), &value, 4, static_cast<off_t>(paths_.registerBase + offset)) != 4)
    fail(fmt::format("xdma: read of register {:#x} from {}", offset, paths_.user));
  return value;
}

void XdmaTransport::writeRegister(std::uint32_t offset, std::uint32_t value) {
  if (::pwrite(user_.get(), &value, 4, static_cast<off_t>(paths_.registerBase + offset)) != 4)
    fail(fmt::format("xdma: write of register {:#x} to {}", offset, paths_.user));
}

void XdmaTransport::postReceive(std::size_t maxWords) {
  receives_.push_back(std::async(std::launch::async, [fd = c2h_.get(), maxWords, path = paths_.c2h] {
    std::vector<std::uint32_t> words(maxWords);
    ssize_t n;
    do n = ::read(fd, words.data(), maxWords * 4);
    while (n < 0 && errno == EINTR);
    if (n < 0) fail(fmt::format("xdma: read of up to {} bytes from {}", maxWords * 4, path));
    words.resize(static_cast<std::size_t>(n) / 4);
    return words;
  }));
}

void XdmaTransport::send(std::span<const std::uint32_t> packet) {
  sends_.push_back(std::async(std::launch::async,
                              [fd = h2c_.get(), words = std::vector<std::uint32_t>(packet.begin(), packet.end()),
                               path = paths_.h2c] { writeAll(fd, words, path); }));
  while (sends_.size() > 1 && sends_.front().wait_for(std::chrono::seconds{0}) == std::future_status::ready) {
    sends_.front().get();  // rethrows a failed transfer
    sends_.pop_front();
  }
}

bool XdmaTransport::receive(std::vector<std::uint32_t>& reply, std::chrono::microseconds timeout) {
  if (receives_.empty() || receives_.front().wait_for(timeout) != std::future_status::ready) return false;
  auto next = std::move(receives_.front());
  receives_.pop_front();
  reply = next.get();
  return true;
}

bool XdmaTransport::waitInterrupt(std::chrono::microseconds timeout) {
  pollfd p{events_.get(), POLLIN, 0};
  const int ready = ::poll(&p, 1, static_cast<int>(std::chrono::ceil<std::chrono::milliseconds>(timeout).count()));
  if (ready < 0 && errno != EINTR) fail("xdma: poll of " + paths_.events);
  if (ready <= 0) return false;
  std::uint32_t count = 0;  // the events file returns the interrupt's count
  if (::read(events_.get(), &count, 4) != 4) fail("xdma: read of " + paths_.events);
  return true;
}

void XdmaTransport::resetChannels() {
  // Transfers cannot be cancelled through the character devices; each ends by
  // the XDMA driver's timeout at the latest, and what it brings is dropped.
  for (auto& s : sends_) s.wait();
  for (auto& r : receives_) r.wait();
  sends_.clear();
  receives_.clear();
}

std::chrono::nanoseconds XdmaTransport::now() { return std::chrono::steady_clock::now().time_since_epoch(); }

}  // namespace bpaccel
