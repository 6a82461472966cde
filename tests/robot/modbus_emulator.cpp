// dg_modbus_emulator: a Modbus TCP server written with libmodbus's server API, standing in for
// the Robotiq FT 300 sensor (holding registers 180-185) and for a robot controller (coils,
// holding registers) in the bridge's tests. Several clients at once (select(), as libmodbus's own
// multi-client example). Fault injection by magic registers, as libmodbus's unit-test-server does:
//   holding register 900 = 0  normal
//                          1  answer every read of register 180 with exception 04 (server failure)
//                          2  never answer a read of register 180 (the client times out)
//                          3  disappear: close every connection and the listening socket for
//                             register 901 milliseconds, then listen again (the sensor unplugged)
//                          4  answer the next read of register 180 register 902 milliseconds
//                             late, then go back to 0 (one late answer)
//   holding register 910      number of reads of register 180 answered (mod 65536)
//   holding register 911      RTU: streams stopped by a jam (mod 65536)
//                    912      RTU: streams started (mod 65536)
// On RTU it is an FT 300 in data stream mode too (firmware-bridge/linux/ft300_stream.h gives the
// sources; this is written from the manual, not from the bridge's code): a write of 0x0200 to
// holding register 410 starts, after its answer, a 16-byte frame every 10 ms: 0x20 0x4E, the
// registers 180-185 as int16 low byte first, CRC-16/MODBUS low byte first over the 14 bytes
// before it. Any 0xFF byte stops the stream; once its input has been quiet for 20 ms it answers
// Modbus again. Other bytes sent to a streaming sensor are ignored.
//
// The registers 180-185 are set by clients (FC06/FC16), e.g. by the test, or at start with
// --hold ADDR=VALUE (repeatable; the SocketCAN VM test, which has no Modbus client, holds a
// force with it).
//
//   dg_modbus_emulator [--port N] [--hold ADDR=VALUE]...
//                                      prints "listening on PORT" (N = 0: any free port)
//   dg_modbus_emulator --rtu DEVICE [--slave N] [--stream 1] [--control 1]
//                                      Modbus RTU (115200 8N1) on a serial device (a pty in the
//                                      tests); prints "serving DEVICE". --stream 1: streaming
//                                      from the start (a sensor left streaming, or just booted).
//                                      --control 1: commands on stdin, one a line, for what
//                                      Modbus cannot reach while the line streams:
//                                        set ADDR V...  holding registers from ADDR (signed too)
//                                        corrupt        one data bit of the next frame flipped,
//                                                       its CRC as before
//                                        junk           a false header, 0x20 0x4E 0x01, before
//                                                       the next frame
//                                        dark MS        a power cut: nothing sent and the input
//                                                       ignored for MS ms, then it streams
#include <arpa/inet.h>
#include <modbus.h>
#include <netinet/in.h>
#include <sys/select.h>
#include <sys/socket.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <chrono>
#include <sstream>
#include <string>
#include <thread>
#include <utility>
#include <vector>

namespace {

constexpr int kFaultMode = 900, kDarkMs = 901, kLateMs = 902, kReadsServed = 910, kFtRegister = 180;
constexpr int kStreamsStopped = 911, kStreamsStarted = 912, kOutputRegister = 410, kStreamOutput = 0x0200;
using Clock = std::chrono::steady_clock;

// Mode 4: sleeps before the answer to a read of the sensor's registers, once.
void maybe_late(modbus_mapping_t* map, bool ft_read) {
  if (!ft_read || map->tab_registers[kFaultMode] != 4) return;
  map->tab_registers[kFaultMode] = 0;
  std::this_thread::sleep_for(std::chrono::milliseconds(map->tab_registers[kLateMs]));
}

int listen_on(modbus_t* ctx, int& port) {
  // modbus_tcp_listen binds the port of the context; for port 0 ask the kernel which it chose.
  const int s = modbus_tcp_listen(ctx, 8);
  if (s < 0) return -1;
  sockaddr_in a{};
  socklen_t len = sizeof a;
  getsockname(s, reinterpret_cast<sockaddr*>(&a), &len);
  port = ntohs(a.sin_port);
  return s;
}

}  // namespace

// The FT 300's data stream: on or off, the faults the next frame carries, a power cut.
struct FtStream {
  bool on = false;
  Clock::time_point next_frame{};
  bool corrupt_next = false, junk_next = false;
  bool dark = false;
  Clock::time_point dark_until{};
};

uint16_t modbus_crc(const uint8_t* p, size_t n) {
  uint16_t crc = 0xFFFF;
  while (n--) {
    crc ^= *p++;
    for (int k = 0; k < 8; ++k) crc = static_cast<uint16_t>((crc >> 1) ^ ((crc & 1) ? 0xA001 : 0));
  }
  return crc;
}

void send_frame(int fd, const uint16_t* regs, FtStream& s) {
  uint8_t out[3 + 16];
  size_t n = 0;
  if (s.junk_next) {
    for (uint8_t b : {0x20, 0x4E, 0x01}) out[n++] = b;
    s.junk_next = false;
  }
  uint8_t* f = out + n;
  f[0] = 0x20;
  f[1] = 0x4E;
  for (int k = 0; k < 6; ++k) {
    f[2 + 2 * k] = static_cast<uint8_t>(regs[k] & 0xFF);
    f[3 + 2 * k] = static_cast<uint8_t>(regs[k] >> 8);
  }
  const uint16_t crc = modbus_crc(f, 14);
  f[14] = static_cast<uint8_t>(crc & 0xFF);
  f[15] = static_cast<uint8_t>(crc >> 8);
  if (s.corrupt_next) {
    f[2] ^= 0x01;
    s.corrupt_next = false;
  }
  [[maybe_unused]] ssize_t w = write(fd, out, n + 16);
}

// Everything the line holds now (libmodbus opened it non-blocking): whether a 0xFF was in it.
bool read_input(int fd) {
  uint8_t buf[256];
  bool jam = false;
  ssize_t n;
  while ((n = read(fd, buf, sizeof buf)) > 0)
    for (ssize_t i = 0; i < n; ++i) jam |= buf[i] == 0xFF;
  return jam;
}

bool readable(int fd, int ms) {
  fd_set rd;
  FD_ZERO(&rd);
  FD_SET(fd, &rd);
  timeval tv{ms / 1000, (ms % 1000) * 1000};
  return select(fd + 1, &rd, nullptr, nullptr, &tv) > 0;
}

// Jammed: the rest of the jam is drained (until 20 ms of quiet), then Modbus again.
void stop_stream(int fd, modbus_mapping_t* map, FtStream& s) {
  s.on = false;
  ++map->tab_registers[kStreamsStopped];
  while (readable(fd, 20)) read_input(fd);
  tcflush(fd, TCIFLUSH);
}

void apply_command(const std::string& line, modbus_mapping_t* map, FtStream& s) {
  std::istringstream in(line);
  std::string cmd;
  in >> cmd;
  if (cmd == "set") {
    int addr = 0;
    long v = 0;
    in >> addr;
    while (in >> v && addr >= 0 && addr < 1000) map->tab_registers[addr++] = static_cast<uint16_t>(v);
  } else if (cmd == "corrupt") {
    s.corrupt_next = true;
  } else if (cmd == "junk") {
    s.junk_next = true;
  } else if (cmd == "dark") {
    int ms = 0;
    in >> ms;
    s.on = false;
    s.dark = true;
    s.dark_until = Clock::now() + std::chrono::milliseconds(ms);
  }
}

// The commands on stdin: false at its end.
bool read_commands(std::string& partial, modbus_mapping_t* map, FtStream& s) {
  char buf[256];
  const ssize_t n = read(0, buf, sizeof buf);
  if (n <= 0) return false;
  partial.append(buf, static_cast<size_t>(n));
  for (size_t eol; (eol = partial.find('\n')) != std::string::npos; partial.erase(0, eol + 1))
    apply_command(partial.substr(0, eol), map, s);
  return true;
}

// One Modbus request, with the fault modes: modbus_receive's result (<= 0: nothing to answer).
// On a line (`s` given) a write of 410 = 0x0200 starts the stream.
int serve_request(modbus_t* ctx, modbus_mapping_t* map, FtStream* s) {
  uint8_t query[MODBUS_TCP_MAX_ADU_LENGTH];
  const int hl = modbus_get_header_length(ctx);
  const int rc = modbus_receive(ctx, query);
  if (rc <= 0) return rc;
  const int function = query[hl];
  const int address = (query[hl + 1] << 8) | query[hl + 2];
  const bool ft_read = (function == 0x03 || function == 0x04) && address == kFtRegister;
  const int mode = map->tab_registers[kFaultMode];
  if (ft_read && mode == 2) return rc;  // silence: the client's response timeout fires
  if (ft_read && mode == 1) {
    modbus_reply_exception(ctx, query, MODBUS_EXCEPTION_SLAVE_OR_SERVER_FAILURE);
    return rc;
  }
  maybe_late(map, ft_read);
  modbus_reply(ctx, query, rc, map);
  if (ft_read) ++map->tab_registers[kReadsServed];
  if (s && map->tab_registers[kOutputRegister] == kStreamOutput) {
    map->tab_registers[kOutputRegister] = 0;
    ++map->tab_registers[kStreamsStarted];
    s->on = true;
    s->next_frame = Clock::now() + std::chrono::milliseconds(10);
  }
  return rc;
}

// The stream's next 10 ms: a frame when due; behind by more than 0.1 s (a stalled host), it
// starts afresh rather than bursting.
void stream_on(int fd, modbus_mapping_t* map, FtStream& s) {
  const auto now = Clock::now();
  if (now < s.next_frame) return;
  send_frame(fd, &map->tab_registers[kFtRegister], s);
  s.next_frame += std::chrono::milliseconds(10);
  if (now - s.next_frame > std::chrono::milliseconds(100)) s.next_frame = now;
}

// RTU: one client on the line; the same registers and fault modes (3 is not available on a
// line), and the FT 300's stream.
int serve_rtu(const char* device, int slave, bool streaming, bool control) {
  modbus_t* ctx = modbus_new_rtu(device, 115200, 'N', 8, 1);
  modbus_mapping_t* map = modbus_mapping_new(1000, 0, 1000, 0);
  // A frame ends after 20 ms of silence (a device's 3.5 characters, with room for this host):
  // the tail of a jam is dropped long before the next request comes.
  if (!ctx || !map || modbus_set_slave(ctx, slave) != 0 || modbus_set_byte_timeout(ctx, 0, 20000) != 0 ||
      modbus_connect(ctx) != 0) {
    std::fprintf(stderr, "dg_modbus_emulator: %s: %s\n", device, modbus_strerror(errno));
    return 1;
  }
  std::printf("serving %s\n", device);
  std::fflush(stdout);
  const int fd = modbus_get_socket(ctx);
  FtStream s;
  s.on = streaming;
  s.next_frame = Clock::now();
  std::string partial;
  for (;;) {
    fd_set rd;
    FD_ZERO(&rd);
    FD_SET(fd, &rd);
    if (control) FD_SET(0, &rd);
    const auto wake = s.dark ? s.dark_until : s.next_frame;
    const auto wait = std::chrono::duration_cast<std::chrono::microseconds>(wake - Clock::now()).count();
    timeval tv{0, 0};
    if (wait > 0) tv = {static_cast<time_t>(wait / 1000000), static_cast<suseconds_t>(wait % 1000000)};
    if (select(fd + 1, &rd, nullptr, nullptr, (s.on || s.dark) ? &tv : nullptr) < 0) {
      if (errno == EINTR) continue;
      return 1;
    }
    if (control && FD_ISSET(0, &rd)) control = read_commands(partial, map, s);
    const bool input = FD_ISSET(fd, &rd);
    if (s.dark) {
      if (input) read_input(fd);
      if (Clock::now() >= s.dark_until) {
        s.dark = false;
        s.on = true;  // it boots streaming
        s.next_frame = Clock::now();
      }
    } else if (s.on) {
      if (input && read_input(fd)) stop_stream(fd, map, s);
      else stream_on(fd, map, s);
    } else if (input) {
      serve_request(ctx, map, &s);  // not for us or garbled (<= 0): wait for the next
    }
  }
}

int main(int argc, char** argv) {
  int port = 0, slave = 9;
  bool streaming = false, control = false;
  const char* rtu = nullptr;
  std::vector<std::pair<int, uint16_t>> holds;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--port")) port = std::atoi(argv[i + 1]);
    if (!std::strcmp(argv[i], "--rtu")) rtu = argv[i + 1];
    if (!std::strcmp(argv[i], "--slave")) slave = std::atoi(argv[i + 1]);
    if (!std::strcmp(argv[i], "--hold")) {
      int addr = -1;
      long value = -1;
      if (std::sscanf(argv[i + 1], "%d=%ld", &addr, &value) != 2 || addr < 0 || addr >= 1000 || value < -32768 ||
          value > 65535) {
        std::fprintf(stderr, "dg_modbus_emulator: --hold %s: expected ADDR=VALUE, ADDR 0..999, VALUE a 16-bit word\n",
                     argv[i + 1]);
        return 2;
      }
      holds.emplace_back(addr, static_cast<uint16_t>(value));
    }
    if (!std::strcmp(argv[i], "--stream")) streaming = std::atoi(argv[i + 1]) != 0;
    if (!std::strcmp(argv[i], "--control")) control = std::atoi(argv[i + 1]) != 0;
  }
  if (rtu) return serve_rtu(rtu, slave, streaming, control);
  modbus_t* ctx = modbus_new_tcp("127.0.0.1", port);
  modbus_mapping_t* map = modbus_mapping_new(1000, 0, 1000, 0);
  if (!ctx || !map) {
    std::fprintf(stderr, "dg_modbus_emulator: %s\n", modbus_strerror(errno));
    return 1;
  }
  for (const auto& [addr, value] : holds) map->tab_registers[addr] = value;
  int server = listen_on(ctx, port);
  if (server < 0) {
    std::fprintf(stderr, "dg_modbus_emulator: listen: %s\n", modbus_strerror(errno));
    return 1;
  }
  // Rebind later to the same port.
  modbus_free(ctx);
  ctx = modbus_new_tcp("127.0.0.1", port);
  std::printf("listening on %d\n", port);
  std::fflush(stdout);
  fd_set refset;
  FD_ZERO(&refset);
  FD_SET(server, &refset);
  int fdmax = server;
  for (;;) {
    fd_set rdset = refset;
    if (select(fdmax + 1, &rdset, nullptr, nullptr, nullptr) < 0) {
      if (errno == EINTR) continue;
      return 1;
    }
    for (int fd = 0; fd <= fdmax; ++fd) {
      if (!FD_ISSET(fd, &rdset)) continue;
      if (fd == server) {
        sockaddr_in a{};
        socklen_t len = sizeof a;
        const int c = accept(server, reinterpret_cast<sockaddr*>(&a), &len);
        if (c >= 0) {
          FD_SET(c, &refset);
          if (c > fdmax) fdmax = c;
        }
        continue;
      }
      modbus_set_socket(ctx, fd);
      if (serve_request(ctx, map, nullptr) <= 0) {
        close(fd);
        FD_CLR(fd, &refset);
        continue;
      }
      if (map->tab_registers[kFaultMode] == 3) {
        // Unplugged: every connection and the listener go away, then come back.
        for (int f = 0; f <= fdmax; ++f)
          if (FD_ISSET(f, &refset)) close(f);
        FD_ZERO(&refset);
        const int dark = map->tab_registers[kDarkMs];
        map->tab_registers[kFaultMode] = 0;
        std::this_thread::sleep_for(std::chrono::milliseconds(dark));
        for (int attempt = 0; attempt < 100 && (server = modbus_tcp_listen(ctx, 8)) < 0; ++attempt)
          std::this_thread::sleep_for(std::chrono::milliseconds(10));  // TIME_WAIT: SO_REUSEADDR is set by libmodbus
        if (server < 0) return 1;
        FD_SET(server, &refset);
        fdmax = server;
        break;
      }
    }
  }
}
