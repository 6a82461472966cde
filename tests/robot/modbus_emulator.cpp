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
// The registers 180-185 are set by clients (FC06/FC16), e.g. by the test, or at start with
// --hold ADDR=VALUE (repeatable; the SocketCAN VM test, which has no Modbus client, holds a
// force with it).
//
//   dg_modbus_emulator [--port N] [--hold ADDR=VALUE]...
//                                      prints "listening on PORT" (N = 0: any free port)
//   dg_modbus_emulator --rtu DEVICE [--slave N]   Modbus RTU (115200 8N1) on a serial device
//                                      (a pty in the tests); prints "serving DEVICE"
#include <arpa/inet.h>
#include <modbus.h>
#include <netinet/in.h>
#include <sys/select.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <chrono>
#include <thread>
#include <utility>
#include <vector>

namespace {

constexpr int kFaultMode = 900, kDarkMs = 901, kLateMs = 902, kReadsServed = 910, kFtRegister = 180;

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

// RTU: one client on the line; the same registers and fault modes (3 is not available on a line).
int serve_rtu(const char* device, int slave) {
  modbus_t* ctx = modbus_new_rtu(device, 115200, 'N', 8, 1);
  modbus_mapping_t* map = modbus_mapping_new(1000, 0, 1000, 0);
  if (!ctx || !map || modbus_set_slave(ctx, slave) != 0 || modbus_connect(ctx) != 0) {
    std::fprintf(stderr, "dg_modbus_emulator: %s: %s\n", device, modbus_strerror(errno));
    return 1;
  }
  std::printf("serving %s\n", device);
  std::fflush(stdout);
  uint8_t query[MODBUS_RTU_MAX_ADU_LENGTH];
  const int hl = modbus_get_header_length(ctx);
  for (;;) {
    const int rc = modbus_receive(ctx, query);
    if (rc <= 0) continue;  // not for us, or a garbled frame: wait for the next
    const int function = query[hl];
    const int address = (query[hl + 1] << 8) | query[hl + 2];
    const bool ft_read = (function == 0x03 || function == 0x04) && address == kFtRegister;
    const int mode = map->tab_registers[kFaultMode];
    if (ft_read && mode == 2) continue;
    if (ft_read && mode == 1) {
      modbus_reply_exception(ctx, query, MODBUS_EXCEPTION_SLAVE_OR_SERVER_FAILURE);
      continue;
    }
    maybe_late(map, ft_read);
    modbus_reply(ctx, query, rc, map);
    if (ft_read) ++map->tab_registers[kReadsServed];
  }
}

int main(int argc, char** argv) {
  int port = 0, slave = 9;
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
  }
  if (rtu) return serve_rtu(rtu, slave);
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
  uint8_t query[MODBUS_TCP_MAX_ADU_LENGTH];
  const int hl = modbus_get_header_length(ctx);
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
      const int rc = modbus_receive(ctx, query);
      if (rc <= 0) {
        close(fd);
        FD_CLR(fd, &refset);
        continue;
      }
      const int function = query[hl];
      const int address = (query[hl + 1] << 8) | query[hl + 2];
      const bool ft_read = (function == 0x03 || function == 0x04) && address == kFtRegister;
      const int mode = map->tab_registers[kFaultMode];
      if (ft_read && mode == 2) continue;  // silence: the client's response timeout fires
      if (ft_read && mode == 1) {
        modbus_reply_exception(ctx, query, MODBUS_EXCEPTION_SLAVE_OR_SERVER_FAILURE);
        continue;
      }
      maybe_late(map, ft_read);
      modbus_reply(ctx, query, rc, map);
      if (ft_read) ++map->tab_registers[kReadsServed];
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
