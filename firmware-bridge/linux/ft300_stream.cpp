// The Robotiq FT 300's data stream on a raw serial line (sources of each detail: the header).
#include "ft300_stream.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/epoll.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <system_error>

namespace dressguard::bridge {
namespace {

constexpr const char* kStreamPrefix = "rtu-stream:";

// "Input/output error (EIO)": the text and the name, as the operator looks either up.
std::string errno_text(int e) {
  const char* name = strerrorname_np(e);
  return std::string(std::strerror(e)) + " (" + (name ? name : std::to_string(e)) + ")";
}

int16_t le16(const uint8_t* p) { return static_cast<int16_t>(p[0] | p[1] << 8); }

long long ms_between(std::chrono::steady_clock::time_point a, std::chrono::steady_clock::time_point b) {
  return std::chrono::duration_cast<std::chrono::milliseconds>(b - a).count();
}

// The answer a unit gives to a write of one register (FC16): its request's first six bytes.
void start_echo(int slave, uint8_t out[8]) {
  uint8_t request[ft300::kStartRequestBytes];
  ft300_start_request(slave, request);
  std::memcpy(out, request, 6);
  const uint16_t crc = crc16_modbus(out, 6);
  out[6] = static_cast<uint8_t>(crc & 0xFF);
  out[7] = static_cast<uint8_t>(crc >> 8);
}

}  // namespace

uint16_t crc16_modbus(const uint8_t* p, size_t n) {
  uint16_t crc = 0xFFFF;
  for (size_t i = 0; i < n; ++i) {
    crc ^= p[i];
    for (int bit = 0; bit < 8; ++bit) crc = (crc & 1) ? static_cast<uint16_t>((crc >> 1) ^ 0xA001) : crc >> 1;
  }
  return crc;
}

void ft300_start_request(int slave, uint8_t out[ft300::kStartRequestBytes]) {
  const uint8_t head[9] = {static_cast<uint8_t>(slave), 0x10,  // FC16, Preset Multiple Registers
                           ft300::kOutputRegister >> 8, ft300::kOutputRegister & 0xFF,
                           0x00, 0x01,                          // one register ...
                           0x02,                                // ... of two bytes
                           ft300::kStreamOutput >> 8, ft300::kStreamOutput & 0xFF};
  std::memcpy(out, head, sizeof head);
  const uint16_t crc = crc16_modbus(out, sizeof head);
  out[9] = static_cast<uint8_t>(crc & 0xFF);
  out[10] = static_cast<uint8_t>(crc >> 8);
}

bool is_stream_spec(const std::string& spec) { return spec.rfind(kStreamPrefix, 0) == 0; }

std::string parse_stream_spec(const std::string& spec, std::string* device) {
  if (!is_stream_spec(spec)) return "'" + spec + "' is not rtu-stream:DEVICE";
  const std::string d = spec.substr(std::strlen(kStreamPrefix));
  if (d.empty()) return "'" + spec + "': no device";
  if (device) *device = d;
  return {};
}

// ---- frames ----------------------------------------------------------------------------------

size_t Ft300FrameParser::space() {
  if (begin_ > 0) {  // keep what is left at the front: room for a whole read behind it
    std::memmove(buf_, buf_ + begin_, end_ - begin_);
    end_ -= begin_;
    begin_ = 0;
  }
  return sizeof buf_ - end_;
}

void Ft300FrameParser::clear() {
  stats_.skipped_bytes += end_ - begin_;
  begin_ = end_ = 0;
  in_step_ = false;
}

void Ft300FrameParser::skip(size_t n) {
  if (in_step_) ++stats_.resyncs;
  in_step_ = false;
  begin_ += n;
  stats_.skipped_bytes += n;
}

ReadResult Ft300FrameParser::next(FtReading& out) {
  while (end_ - begin_ >= 2) {
    const uint8_t* f = buf_ + begin_;
    if (f[0] != ft300::kHeader[0] || f[1] != ft300::kHeader[1]) {
      skip(1);
      continue;
    }
    if (end_ - begin_ < ft300::kFrameBytes) return ReadResult::Pending;
    if (crc16_modbus(f, ft300::kCrcBytes) != static_cast<uint16_t>(le16(f + ft300::kCrcBytes))) {
      ++stats_.crc_failures;
      const bool due = in_step_;  // where the next frame was due: it is lost
      skip(1);                    // the frame may begin after this false or damaged header
      if (due) return ReadResult::BadData;
      continue;  // a false header met while finding the next frame: counted, not one more loss
    }
    for (int k = 0; k < 3; ++k) {
      out.force[k] = le16(f + 2 + 2 * k);   // Fx Fy Fz x 100: already the protocol's 0.01 N
      out.torque[k] = le16(f + 8 + 2 * k);  // Mx My Mz x 1000: already its 0.001 Nm
    }
    begin_ += ft300::kFrameBytes;
    in_step_ = true;
    ++stats_.frames;
    return ReadResult::Ok;
  }
  // A lone last byte that cannot begin a header is no part of a frame.
  if (end_ - begin_ == 1 && buf_[begin_] != ft300::kHeader[0]) skip(1);
  return ReadResult::Pending;
}

// ---- the line --------------------------------------------------------------------------------

Ft300Stream::Ft300Stream(Ft300StreamConfig cfg) : cfg_(std::move(cfg)) {
  // One descriptor for the bridge's loop to watch, whatever the line's own is after a reopen.
  epoll_fd_ = epoll_create1(EPOLL_CLOEXEC);
  if (epoll_fd_ < 0) throw std::system_error(errno, std::generic_category(), "epoll_create1");
}

Ft300Stream::~Ft300Stream() {
  close();
  ::close(epoll_fd_);
}

void Ft300Stream::close() {
  if (tty_ < 0) return;
  epoll_ctl(epoll_fd_, EPOLL_CTL_DEL, tty_, nullptr);  // a failure here leaves nothing to undo
  ::close(tty_);
  tty_ = -1;
}

ReadResult Ft300Stream::fail(ReadResult why, const std::string& what) {
  error_ = cfg_.device + ": " + what;
  return closed(why);
}

ReadResult Ft300Stream::closed(ReadResult why) {
  close();
  return why;
}

bool Ft300Stream::configure_line() {
  const auto failed = [this](const char* call) {
    error_ = cfg_.device + ": " + call + ": " + errno_text(errno);
    return false;
  };
  termios t{};
  if (tcgetattr(tty_, &t) != 0) return failed("tcgetattr");
  cfmakeraw(&t);  // no echo, no line editing, no CR/LF mapping, no signals: bytes as they come
  t.c_cflag &= ~(CSIZE | PARENB | CSTOPB | CRTSCTS);
  t.c_cflag |= CS8 | CLOCAL | CREAD;  // [M] 8N1; no modem control, no flow control
  t.c_iflag &= ~(IXON | IXOFF | IXANY);
  // With O_NONBLOCK, VMIN 1 makes an empty line EAGAIN and keeps 0 for a hang-up (VMIN 0 would
  // return 0 for both).
  t.c_cc[VMIN] = 1;
  t.c_cc[VTIME] = 0;
  if (cfsetispeed(&t, B19200) != 0) return failed("cfsetispeed");
  if (cfsetospeed(&t, B19200) != 0) return failed("cfsetospeed");
  if (tcsetattr(tty_, TCSANOW, &t) != 0) return failed("tcsetattr");
  // tcsetattr succeeds when any one change took: read back what the driver kept.
  termios got{};
  if (tcgetattr(tty_, &got) != 0) return failed("tcgetattr");
  if (cfgetispeed(&got) != B19200 || cfgetospeed(&got) != B19200 ||
      (got.c_cflag & (CSIZE | PARENB | CSTOPB)) != CS8) {
    error_ = cfg_.device + ": the line did not take 19200 8N1";
    return false;
  }
  if (tcflush(tty_, TCIOFLUSH) != 0) return failed("tcflush");  // nothing from before this open
  return true;
}

bool Ft300Stream::open_line() {
  close();
  tty_ = ::open(cfg_.device.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (tty_ < 0) {
    error_ = cfg_.device + ": open: " + errno_text(errno);
    return false;
  }
  if (!configure_line()) {
    close();
    return false;
  }
  epoll_event ev{};
  ev.events = EPOLLIN;
  if (epoll_ctl(epoll_fd_, EPOLL_CTL_ADD, tty_, &ev) != 0) {
    error_ = cfg_.device + ": epoll_ctl: " + errno_text(errno);
    close();
    return false;
  }
  const Clock::time_point now = Clock::now();
  parser_.clear();
  phase_ = Phase::Jamming;
  phase_start_ = last_rx_ = now;  // quiet counts from the open
  jammed_ = heard_since_burst_ = false;
  reply_len_ = 0;
  return true;
}

bool Ft300Stream::connect() {
  if (!open_line()) return false;
  error_.clear();
  return true;
}

bool Ft300Stream::write_all(const uint8_t* p, size_t n, const char* what) {
  // A few bytes into an empty output queue of kilobytes: EAGAIN or a short write means a line
  // that does not drain, as good as a lost one.
  const ssize_t w = ::write(tty_, p, n);
  if (w == static_cast<ssize_t>(n)) return true;
  error_ = cfg_.device + ": writing " + what + ": " +
           (w < 0 ? errno_text(errno) : std::to_string(w) + " of " + std::to_string(n) + " bytes written");
  return false;
}

// Non-blocking: everything the line holds now (as much as the parser has room for).
ReadResult Ft300Stream::take_bytes() {
  for (;;) {
    const size_t room = parser_.space();
    if (room == 0) return ReadResult::Ok;
    const ssize_t n = ::read(tty_, parser_.tail(), room);
    if (n > 0) {
      if (phase_ == Phase::Starting && reply_len_ < sizeof reply_) {
        const size_t k = std::min(sizeof reply_ - reply_len_, static_cast<size_t>(n));
        std::memcpy(reply_ + reply_len_, parser_.tail(), k);
        reply_len_ += k;
      }
      parser_.added(static_cast<size_t>(n));
      last_rx_ = Clock::now();
      heard_since_burst_ = true;
      if (phase_ == Phase::Jamming) parser_.clear();  // a stream being stopped: nothing to read in it
      continue;
    }
    if (n == 0) return fail(ReadResult::Disconnected, "the line hung up (adapter unplugged?)");
    if (errno == EAGAIN || errno == EWOULDBLOCK) return ReadResult::Ok;
    if (errno != EINTR) return fail(ReadResult::Disconnected, "read: " + errno_text(errno));
  }
}

// [R]: a burst of 0xFF whenever bytes came since the last one (once it has left the line),
// until nothing has come for quiet_ms and the sensor had switch_ms to go back to Modbus.
Ft300Stream::Jam Ft300Stream::jam_step(Clock::time_point now, int give_up_ms) {
  if (heard_since_burst_ && (!jammed_ || ms_between(last_burst_, now) >= ft300::kJamLineMs)) {
    uint8_t burst[ft300::kJamBytes];
    std::memset(burst, ft300::kJamByte, sizeof burst);
    if (!write_all(burst, sizeof burst, "the jam")) return Jam::LineFailed;
    if (!jammed_) ++stats_.streams_found;
    jammed_ = true;
    heard_since_burst_ = false;
    last_burst_ = now;
  }
  if (ms_between(last_rx_, now) >= cfg_.quiet_ms && (!jammed_ || ms_between(last_burst_, now) >= cfg_.switch_ms))
    return Jam::Quiet;
  if (ms_between(phase_start_, now) >= give_up_ms) {
    error_ = cfg_.device + ": the line did not go quiet after " + std::to_string(give_up_ms) +
             " ms of jamming (a sensor that does not stop, or another device on the line)";
    return Jam::GaveUp;
  }
  return Jam::Going;
}

ReadResult Ft300Stream::on_jamming(Clock::time_point now) {
  const Jam j = jam_step(now, cfg_.jam_give_up_ms);
  if (j == Jam::GaveUp) return closed(ReadResult::Timeout);
  if (j == Jam::LineFailed) return closed(ReadResult::Disconnected);
  if (j == Jam::Going) return ReadResult::Pending;
  // Quiet: the sensor answers Modbus; ask it for the stream.
  uint8_t request[ft300::kStartRequestBytes];
  ft300_start_request(cfg_.slave, request);
  if (!write_all(request, sizeof request, "the start request")) return closed(ReadResult::Disconnected);
  parser_.clear();
  reply_len_ = 0;
  phase_ = Phase::Starting;
  phase_start_ = now;
  return ReadResult::Pending;
}

// What the start request's answer was, for the error when no frame follows it.
std::string Ft300Stream::reply_said() const {
  uint8_t echo[8];
  start_echo(cfg_.slave, echo);
  if (reply_len_ == sizeof echo && std::memcmp(reply_, echo, sizeof echo) == 0) return "the sensor acknowledged it";
  if (reply_len_ >= 5 && reply_[0] == cfg_.slave && reply_[1] == (0x10 | 0x80) &&
      crc16_modbus(reply_, 3) == static_cast<uint16_t>(reply_[3] | reply_[4] << 8))
    return "the sensor answered Modbus exception " + std::to_string(reply_[2]);
  if (reply_len_ == 0) return "no answer";
  return "an answer that is neither its acknowledgement nor an exception";
}

ReadResult Ft300Stream::on_starting(FtReading& out, Clock::time_point now) {
  // The first good frame is the start's success, whatever became of the answer ([R] forgives
  // a lost one). Not yet in step, the parser says Ok or Pending (a false header before the
  // first frame is counted, not returned).
  if (parser_.next(out) == ReadResult::Ok) {
    phase_ = Phase::Streaming;
    last_good_ = now;
    ++stats_.starts;
    return ReadResult::Ok;
  }
  if (ms_between(phase_start_, now) < cfg_.silence_ms) return ReadResult::Pending;
  return fail(ReadResult::Timeout, "no stream frame within " + std::to_string(cfg_.silence_ms) +
                                       " ms of the start request (register " + std::to_string(ft300::kOutputRegister) +
                                       " = 0x0200 on unit " + std::to_string(cfg_.slave) + "): " + reply_said() +
                                       counts());
}

std::string Ft300Stream::counts() const {
  return " (" + std::to_string(stats_.crc_failures.load()) + " CRC failures, " +
         std::to_string(stats_.skipped_bytes.load()) + " bytes in no frame so far)";
}

ReadResult Ft300Stream::next_frame(FtReading& out, Clock::time_point now) {
  const ReadResult r = parser_.next(out);
  if (r == ReadResult::Ok) last_good_ = now;
  if (r == ReadResult::BadData) error_ = cfg_.device + ": a stream frame failed its CRC: not published" + counts();
  return r;
}

ReadResult Ft300Stream::read(FtReading& out) {
  if (tty_ < 0) return ReadResult::Disconnected;
  if (phase_ == Phase::Streaming) {  // frames taken in an earlier call first
    const ReadResult r = next_frame(out, Clock::now());
    if (r != ReadResult::Pending) return r;
  }
  if (const ReadResult r = take_bytes(); r != ReadResult::Ok) return r;
  const Clock::time_point now = Clock::now();
  if (phase_ == Phase::Jamming) return on_jamming(now);
  if (phase_ == Phase::Starting) return on_starting(out, now);
  const ReadResult r = next_frame(out, now);
  if (r != ReadResult::Pending || ms_between(last_good_, now) < cfg_.silence_ms) return r;
  return fail(ReadResult::Timeout, "no good stream frame for " + std::to_string(ms_between(last_good_, now)) +
                                       " ms" + counts());
}

bool Ft300Stream::stop_stream(int give_up_ms) {
  const bool streamed = tty_ >= 0 && phase_ != Phase::Jamming;
  if (!open_line()) return false;  // reopened: its state no longer matters, only the jam's
  heard_since_burst_ = streamed;  // a stream we started: jam it at once, without waiting for its bytes
  for (;;) {
    if (take_bytes() != ReadResult::Ok) return false;
    const Jam j = jam_step(Clock::now(), give_up_ms);
    if (j != Jam::Going) {
      close();
      return j == Jam::Quiet;
    }
    pollfd p{tty_, POLLIN, 0};
    if (poll(&p, 1, 5) < 0 && errno != EINTR) {
      error_ = cfg_.device + ": poll: " + errno_text(errno);
      close();
      return false;
    }
  }
}

}  // namespace dressguard::bridge
