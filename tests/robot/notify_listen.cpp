// dg_notify_listen: stands in for systemd's notification socket in the SocketCAN VM test, where
// no systemd runs. Listens on ADDRESS (a path, or '@' and an abstract name) as systemd does
// (SO_PASSCRED: each message comes with its sender's process ID) until SIGTERM or SIGINT, then
// prints what it heard, one line per message kind:
//   MESSAGE count=N pid=P first_ms=T [max_gap_ms=G]
// in the order each kind first came (first_ms from the listener's start; max_gap_ms, for a kind
// heard more than once, the longest time between two of them: for WATCHDOG=1, how near the
// daemon's loop came to its watchdog's limit). A sender other than the first is named too.
// STATUS= lines are one kind, whatever they say: "STATUS= count=N ..." and then the first and
// the last one heard, as "status_first TEXT" and "status_last TEXT".
//   usage: dg_notify_listen ADDRESS
#include <poll.h>
#include <signal.h>
#include <time.h>

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "notify_listener.h"

namespace {

volatile sig_atomic_t g_stop = 0;
void on_signal(int) { g_stop = 1; }

double now_ms() {
  timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec * 1e3 + ts.tv_nsec / 1e6;
}

struct Kind {
  std::string message;
  long count = 0;
  pid_t pid = 0;
  bool other_sender = false;
  double first_ms = 0, last_ms = 0, max_gap_ms = 0;
};

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: dg_notify_listen ADDRESS   (a path, or '@' and an abstract name)\n");
    return 2;
  }
  dressguard::testkit::NotifyListener listener{std::string(argv[1])};
  if (!listener.error.empty()) {
    std::fprintf(stderr, "dg_notify_listen: %s\n", listener.error.c_str());
    return 1;
  }
  struct sigaction sa{};
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);  // no SA_RESTART: poll returns EINTR
  if (sigaction(SIGTERM, &sa, nullptr) != 0 || sigaction(SIGINT, &sa, nullptr) != 0) {
    std::perror("dg_notify_listen: sigaction");
    return 1;
  }
  std::printf("listening on %s\n", listener.address.c_str());
  std::fflush(stdout);
  const double t0 = now_ms();
  std::vector<Kind> kinds;
  std::string status_first, status_last;
  while (!g_stop) {
    pollfd p{listener.fd, POLLIN, 0};
    if (poll(&p, 1, 100) <= 0) continue;
    pid_t sender = 0;
    for (std::string m; !(m = listener.receive(&sender)).empty();) {
      for (char& c : m)
        if (c == '\n') c = ' ';  // one message, one line
      const double t = now_ms() - t0;
      if (m.rfind("STATUS=", 0) == 0) {
        if (status_first.empty()) status_first = m.substr(7);
        status_last = m.substr(7);
        m = "STATUS=";
      }
      Kind* k = nullptr;
      for (Kind& x : kinds)
        if (x.message == m) k = &x;
      if (!k) {
        kinds.push_back({m, 0, sender, false, t, t, 0});
        k = &kinds.back();
      } else {
        k->max_gap_ms = std::max(k->max_gap_ms, t - k->last_ms);
        k->last_ms = t;
      }
      ++k->count;
      if (sender != k->pid) k->other_sender = true;
    }
  }
  for (const Kind& k : kinds) {
    std::printf("%s count=%ld pid=%d first_ms=%.0f", k.message.c_str(), k.count, static_cast<int>(k.pid), k.first_ms);
    if (k.count > 1) std::printf(" max_gap_ms=%.0f", k.max_gap_ms);
    std::printf("%s\n", k.other_sender ? " other_senders" : "");
  }
  if (!status_first.empty())
    std::printf("status_first %s\nstatus_last %s\n", status_first.c_str(), status_last.c_str());
  return 0;
}
