// SimTest: the SystemC base pieces (model/sim): a two-unit pipeline over an sc_fifo spends the
// cycles its configs say, counts busy cycles, and SystemC warnings become failures.
#include <gtest/gtest.h>

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

// A SystemC warning throws instead of being printed and ignored.
TEST(SimTest, WarningsThrow) {
  install_report_handler();
  EXPECT_THROW(SC_REPORT_WARNING("nbsim/test", "a warning"), std::runtime_error);
}

}  // namespace
}  // namespace nbsim::sim
