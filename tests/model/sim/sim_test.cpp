// SimTest: the SystemC base pieces (model/sim): a two-unit pipeline over an sc_fifo spends the
// cycles its configs say, counts busy cycles, and SystemC warnings become failures.
#include <gtest/gtest.h>

#include "model/common/error.h"
#include "model/sim/unit.h"

extern "C" int sc_main(int, char*[]) { return 1; }  // libsystemc's main() needs one; gtest's main runs

namespace nbsim::sim {
namespace {

struct Producer : Unit {
  sc_core::sc_fifo_out<int> out;
  int batches, latency;
  SC_HAS_PROCESS(Producer);
  Producer(const sc_core::sc_module_name& n, stats::Registry& r, int b, int lat) : Unit(n, r), batches(b), latency(lat) {
    SC_THREAD(run);
  }
  void run() {
    for (int i = 0; i < batches; ++i) {
      work(batch_cycles(64, 16.0, latency));  // 64 items at 16 a cycle, after the latency
      out.write(i);
    }
  }
};

struct Consumer : Unit {
  sc_core::sc_fifo_in<int> in;
  int expected, got = 0;
  std::uint64_t done_at = 0;
  SC_HAS_PROCESS(Consumer);
  Consumer(const sc_core::sc_module_name& n, stats::Registry& r, int e) : Unit(n, r), expected(e) { SC_THREAD(run); }
  void run() {
    while (got < expected) {
      in.read();
      work(2);
      ++got;
    }
    done_at = now_cycles();
  }
};

// Latency and throughput in the configs set the cycles; the consumer overlaps with the producer.
TEST(SimTest, PipelineSpendsConfiguredCycles) {
  install_report_handler();
  stats::Registry reg;
  Producer p("producer", reg, 10, 3);
  Consumer c("consumer", reg, 10);
  sc_core::sc_fifo<int> fifo("fifo", 2);
  p.out(fifo);
  c.in(fifo);
  sc_core::sc_start();
  EXPECT_EQ(c.got, 10);
  EXPECT_EQ(c.done_at, 10u * (4 + 3) + 2) << "ten producer batches of 4 + 3 cycles, then the last consume";
  EXPECT_EQ(reg.values()["producer"]["busy_cycles"], 70);
  EXPECT_EQ(reg.values()["consumer"]["busy_cycles"], 20);
}

// A unit whose thread, after `at` cycles, meets a record it cannot handle (an InputError), and
// then would go on forever.
struct Failing : Unit {
  sc_core::sc_fifo_out<int> out;
  int at;
  SC_HAS_PROCESS(Failing);
  Failing(const sc_core::sc_module_name& n, stats::Registry& r, int a) : Unit(n, r), at(a) { SC_THREAD(run); }
  void run() {
    guard_thread([this] {
      work(static_cast<std::uint64_t>(at));
      out.write(1);
      throw InputError("frame 3: a record the model cannot replay");
    });
  }
};

// An exception in a unit's thread ends the run cleanly: sc_start returns (the consumer, still
// waiting for data, and a DelayLine's thread are left behind), and the driver gets the first
// exception back as it was thrown, with its message (SystemC would otherwise terminate the process).
TEST(SimTest, ThreadExceptionEndsTheRun) {
  install_report_handler();
  stats::Registry reg;
  Failing f("failing", reg, 5);
  Consumer c("consumer", reg, 10);
  DelayLine<int> line("line", 4);
  sc_core::sc_fifo<int> fifo("fifo", 2), delayed("delayed", 2);
  f.out(fifo);
  c.in(delayed);
  line.out(delayed);
  sc_core::sc_start();
  EXPECT_EQ(now_cycles(), 5u) << "the run stops where the thread failed";
  EXPECT_EQ(c.got, 0);
  try {
    rethrow_thread_failure();
    ADD_FAILURE() << "the thread's exception must reach the driver";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "frame 3: a record the model cannot replay");
  }
  EXPECT_NO_THROW(rethrow_thread_failure()) << "reported once";
}

// A SystemC warning throws instead of being printed and ignored.
TEST(SimTest, WarningsThrow) {
  install_report_handler();
  EXPECT_THROW(SC_REPORT_WARNING("nbsim/test", "a warning"), std::runtime_error);
}

}  // namespace
}  // namespace nbsim::sim
