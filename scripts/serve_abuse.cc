// Load generator of scripts/serve-abuse.sh: raw WebSocket clients on loopback against a running
// `frenetic serve`. One well-behaved client (a simulator: one telemetry frame every --period
// ms, each reply checked) is timed while the others abuse the server; what it measured is
// printed as one JSON line. Measures, never asserts: tests/net/abuse_test.cc asserts behaviour.
//
//   frenetic_serve_abuse --port P --mode MODE [--abusers N] [--seconds S] [--frames FILE]
//
// MODE: none (the timed client alone), flood (abusers send telemetry back to back and read
// each reply), pipeline (abusers send telemetry as fast as the socket takes it and never
// read), huge (abusers send 1 MiB frames: 50,000 sensor rows, a 60,000-point path, 1 MiB of
// padding, a 1 MiB string, in turn, and read each reply), dense (abusers send the costliest
// frames within the limits: 2,500 32-digit numbers, 64 rows and 1,000 path points), churn
// (abusers connect, plan once and close, over and over), refuse (N idle connections fill the
// server, then --cycles connections are timed from connect to the 503), cycles (--cycles
// sequential connect / telemetry / close, for the memory figure; nothing timed).
// FILE holds one telemetry frame per line (42["telemetry",{...}]), replayed in order by every
// client; without it a synthetic frame is used.
#include <netinet/tcp.h>
#include <pthread.h>
#include <sched.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "frenetic/wire/protocol.h"
#include "net/net_test_util.h"
#include "net/raw_websocket.h"

namespace {

using frenetic::wire::ParsedReply;
using frenetic::wire::ParseReply;
using frenetic::wire::ReplyKind;
namespace t = frenetic::net::testing;
using Clock = std::chrono::steady_clock;

struct Args {
  int port = 0;
  std::string mode = "none";
  int abusers = 7;
  double seconds = 20;
  double period_ms = 20;
  int cycles = 500;
  std::string frames_path;
};

[[noreturn]] void Usage(const std::string& why) {
  std::fprintf(stderr, "frenetic_serve_abuse: %s\n", why.c_str());
  std::exit(2);
}

Args Parse(int argc, char** argv) {
  Args a;
  for (int i = 1; i < argc; ++i) {
    const std::string k = argv[i];
    if (i + 1 >= argc) Usage(k + " needs a value");
    const std::string v = argv[++i];
    if (k == "--port")
      a.port = std::atoi(v.c_str());
    else if (k == "--mode")
      a.mode = v;
    else if (k == "--abusers")
      a.abusers = std::atoi(v.c_str());
    else if (k == "--seconds")
      a.seconds = std::atof(v.c_str());
    else if (k == "--period")
      a.period_ms = std::atof(v.c_str());
    else if (k == "--cycles")
      a.cycles = std::atoi(v.c_str());
    else if (k == "--frames")
      a.frames_path = v;
    else
      Usage("unknown option " + k);
  }
  if (a.port <= 0) Usage("--port is required");
  return a;
}

std::vector<std::string> LoadFrames(const std::string& path) {
  std::vector<std::string> frames;
  if (path.empty()) {
    frames.push_back(t::FirstTelemetryFrame());
    return frames;
  }
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("42[", 0) == 0) frames.push_back(line);
  }
  if (frames.empty()) Usage(path + ": no 42[\"telemetry\",...] lines");
  return frames;
}

// An upgraded connection with TCP_NODELAY, as the simulator's.
t::RawSocket Open(int port) {
  t::RawSocket s = t::ConnectUpgraded(port);
  if (s.ok()) {
    int one = 1;
    ::setsockopt(s.fd(), IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
  }
  return s;
}

std::string Masked(const std::string& payload) {
  return t::EncodeRawFrame(t::kOpText, payload, /*mask=*/true);
}

double Percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(q * v.size()))];
}

// The 1 MiB frames of issue 22 and its kin.
std::vector<std::string> HugeFrames() {
  const std::size_t kMiB = 1 << 20;
  std::string rows = t::FrameWithRows(0);
  rows.resize(rows.size() - 3);  // reopen sensor_fusion
  for (int i = 0; rows.size() + 80 < kMiB - 64; ++i) {
    if (i > 0) rows += ',';
    rows += t::SensorRow(i);
  }
  rows += "]}]";
  return {rows, t::FrameWithPath(55000), t::FrameWithJunk(std::string(kMiB - 400, ' ') + "1"),
          t::FrameWithJunk("\"" + std::string(kMiB - 400, 'a') + "\"")};
}

// The costliest frames within the default limits (~1 ms each to convert).
std::vector<std::string> DenseFrames() {
  std::string numbers = "[";
  for (int i = 0; i < 2500; ++i) {
    if (i > 0) numbers += ',';
    numbers += "0." + std::string(30, '7');
  }
  return {t::FrameWithJunk(numbers + "]"), t::FrameWithRows(64), t::FrameWithPath(1000)};
}

struct Timed {
  std::vector<double> ms;
  int wrong = 0;  // replies that were not a control (or none at all)
  std::string first_wrong;
};

// The simulator: a frame every period, each reply timed and checked.
void WellBehaved(const Args& a, const std::vector<std::string>& frames, Clock::time_point end,
                 Timed* out) {
  t::RawSocket s = Open(a.port);
  if (!s.ok()) {
    out->wrong = 1;
    out->first_wrong = "cannot connect";
    return;
  }
  ParsedReply reply;
  auto next = Clock::now();
  for (std::size_t i = 0; Clock::now() < end; ++i) {
    const std::string frame = Masked(frames[i % frames.size()]);
    std::this_thread::sleep_until(next);
    next += std::chrono::microseconds(static_cast<std::int64_t>(a.period_ms * 1000));
    const auto t0 = Clock::now();
    if (!s.WriteAll(frame)) {
      ++out->wrong;
      out->first_wrong = "send failed";
      return;
    }
    const auto f = t::ReadRawFrame(s, 10.0);
    const auto t1 = Clock::now();
    if (!f.has_value()) {
      ++out->wrong;
      out->first_wrong = "no reply within 10 s";
      return;
    }
    ParseReply(f->payload, &reply);
    if (reply.kind != ReplyKind::kControl && out->wrong++ == 0) {
      out->first_wrong = f->payload.substr(0, 120);
      for (char& c : out->first_wrong) {
        if (c == '"' || c == '\\' || static_cast<unsigned char>(c) < 0x20) c = '?';
      }
    }
    out->ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
  }
}

// Abusers run at the normal policy even when the tool runs under chrt (which then applies to
// the timed client only).
void Demote() {
  const sched_param normal{};
  (void)pthread_setschedparam(pthread_self(), SCHED_OTHER, &normal);
}

// An abuser sending `frames` in turn; reads each reply unless `pipeline`.
void Abuser(const Args& a, const std::vector<std::string>& frames, bool pipeline,
            Clock::time_point end, std::atomic<long>* sent) {
  Demote();
  std::vector<std::string> masked;
  for (const std::string& f : frames) masked.push_back(Masked(f));
  t::RawSocket s = Open(a.port);
  if (!s.ok()) return;
  if (pipeline) s.SetNonBlocking();
  std::size_t i = 0, offset = 0;
  while (Clock::now() < end) {
    const std::string& frame = masked[i % masked.size()];
    if (pipeline) {
      const std::int64_t n = s.WriteSome(std::string_view(frame).substr(offset));
      if (n < 0) return;  // closed by the server (it stopped reading us: write timeout)
      offset += static_cast<std::size_t>(n);
      if (offset == frame.size()) {
        offset = 0;
        ++i;
        ++*sent;
      } else if (n == 0) {
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
      }
      continue;
    }
    if (!s.WriteAll(frame) || !t::ReadRawFrame(s, 10.0).has_value()) {
      s = Open(a.port);  // closed (e.g. an oversize frame): come back
      if (!s.ok()) return;
      continue;
    }
    ++i;
    ++*sent;
  }
}

void Churner(const Args& a, const std::vector<std::string>& frames, Clock::time_point end,
             int max_cycles, std::atomic<long>* cycles) {
  Demote();
  const std::string close = t::EncodeCloseFrame(1000, "", /*mask=*/true);
  for (long i = 0; Clock::now() < end && (max_cycles <= 0 || i < max_cycles); ++i) {
    t::RawSocket s = Open(a.port);
    if (!s.ok()) {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));  // at the cap: try again
      continue;
    }
    s.WriteAll(Masked(frames[static_cast<std::size_t>(i) % frames.size()]));
    t::ReadRawFrame(s, 10.0);
    s.WriteAll(close);
    t::ReadRawFrame(s, 1.0);
    ++*cycles;
  }
}

int Refuse(const Args& a) {
  std::vector<t::RawSocket> held;
  for (int i = 0; i < a.abusers; ++i) {
    held.push_back(Open(a.port));
    if (!held.back().ok()) Usage("could not open connection " + std::to_string(i + 1));
  }
  std::vector<double> ms;
  int not_503 = 0;
  std::string example;
  for (int i = 0; i < a.cycles; ++i) {
    const auto t0 = Clock::now();
    t::RawSocket s = t::RawSocket::Connect(a.port);
    std::string response;
    const bool answered = s.ok() && t::UpgradeByHand(s, a.port, &response);
    const auto t1 = Clock::now();
    if (!answered || response.rfind("HTTP/1.1 503", 0) != 0) {
      ++not_503;
      continue;
    }
    if (example.empty()) s.ReadUntil("\n", &example);
    ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
  }
  if (!example.empty() && example.back() == '\n') example.pop_back();
  std::printf(
      "{\"mode\":\"refuse\",\"held\":%d,\"refusals\":%zu,\"not_503\":%d,\"p50_ms\":%.3f,"
      "\"p99_ms\":%.3f,\"max_ms\":%.3f,\"reason\":\"%s\"}\n",
      a.abusers, ms.size(), not_503, Percentile(ms, 0.5), Percentile(ms, 0.99),
      ms.empty() ? 0.0 : *std::max_element(ms.begin(), ms.end()), example.c_str());
  return not_503 == 0 ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  const Args a = Parse(argc, argv);
  const std::vector<std::string> frames = LoadFrames(a.frames_path);
  if (a.mode == "refuse") return Refuse(a);
  std::atomic<long> sent{0};
  if (a.mode == "cycles") {
    Churner(a, frames, Clock::now() + std::chrono::hours(1), a.cycles, &sent);
    std::printf("{\"mode\":\"cycles\",\"cycles\":%ld}\n", sent.load());
    return sent == a.cycles ? 0 : 1;
  }
  const auto end = Clock::now() + std::chrono::milliseconds(static_cast<long>(a.seconds * 1000));
  std::vector<std::thread> threads;
  const int abusers = a.mode == "none" ? 0 : a.abusers;
  std::vector<std::string> abuse = frames;
  if (a.mode == "huge") abuse = HugeFrames();
  if (a.mode == "dense") abuse = DenseFrames();
  for (int i = 0; i < abusers; ++i) {
    if (a.mode == "churn") {
      threads.emplace_back([&] { Churner(a, frames, end, 0, &sent); });
    } else if (a.mode == "flood" || a.mode == "pipeline" || a.mode == "huge" || a.mode == "dense") {
      threads.emplace_back([&, i] {
        // Each abuser starts at its own place in the drive.
        std::vector<std::string> mine(abuse.begin() + (i * 37) % abuse.size(), abuse.end());
        mine.insert(mine.end(), abuse.begin(), abuse.begin() + (i * 37) % abuse.size());
        Abuser(a, mine, a.mode == "pipeline", end, &sent);
      });
    } else {
      Usage("unknown mode " + a.mode);
    }
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(200));  // the abuse is under way
  Timed timed;
  WellBehaved(a, frames, end, &timed);
  for (std::thread& th : threads) th.join();
  // The session's first replies include building its planner (and run as heavy work): shown
  // apart, with the figures of the replies after them.
  constexpr std::size_t kFirst = 10;
  const std::size_t first = std::min(kFirst, timed.ms.size());
  const std::vector<double> later(timed.ms.begin() + static_cast<std::ptrdiff_t>(first),
                                  timed.ms.end());
  auto max_of = [](const std::vector<double>& v) {
    return v.empty() ? 0.0 : *std::max_element(v.begin(), v.end());
  };
  std::printf(
      "{\"mode\":\"%s\",\"abusers\":%d,\"replies\":%zu,\"wrong\":%d,\"p50_ms\":%.3f,"
      "\"p99_ms\":%.3f,\"max_ms\":%.3f,\"first10_max_ms\":%.3f,\"later_p99_ms\":%.3f,"
      "\"later_max_ms\":%.3f,\"abuser_frames\":%ld%s}\n",
      a.mode.c_str(), abusers, timed.ms.size(), timed.wrong, Percentile(timed.ms, 0.5),
      Percentile(timed.ms, 0.99), max_of(timed.ms),
      max_of(std::vector<double>(timed.ms.begin(),
                                 timed.ms.begin() + static_cast<std::ptrdiff_t>(first))),
      Percentile(later, 0.99), max_of(later), sent.load(),
      timed.first_wrong.empty() ? "" : (",\"first_wrong\":\"" + timed.first_wrong + "\"").c_str());
  return timed.wrong == 0 ? 0 : 1;
}
