// QuantumTest: temporal decoupling in model/sim (quantum.h, Unit::work, DelayLine): a thread runs
// ahead of SystemC time and synchronises at multiples of the quantum, a blocked thread resumes at
// the later of its local time and SystemC's, and quantum 1 times a pipeline exactly as no quantum.
// One simulation per TEST (each runs in its own process).
#include <gtest/gtest.h>

#include <vector>

#include "model/sim/unit.h"

extern "C" int sc_main(int, char*[]) { return 1; }  // libsystemc's main() needs one; gtest's main runs

namespace nbsim::sim {
namespace {

struct Worker : Unit {
  int items;
  std::uint64_t each;
  std::vector<std::uint64_t> local, systemc;  // after each work item
  SC_HAS_PROCESS(Worker);
  Worker(const sc_core::sc_module_name& n, stats::Registry& r, int k, std::uint64_t c) : Unit(n, r), items(k), each(c) {
    SC_THREAD(run);
  }
  void run() {
    for (int i = 0; i < items; ++i) {
      work(each);
      local.push_back(local_cycles());
      systemc.push_back(now_cycles());
    }
  }
};

// With a quantum, work() moves the local time on and SystemC time only at multiples of the quantum.
TEST(QuantumTest, WorkRunsAheadAndSyncsAtQuantum) {
  install_report_handler();
  set_quantum_cycles(100);
  stats::Registry reg;
  Worker w("worker", reg, 25, 10);
  sc_core::sc_start();
  ASSERT_EQ(w.local.size(), 25u);
  for (std::size_t i = 0; i < w.local.size(); ++i) {
    EXPECT_EQ(w.local[i], 10 * (i + 1)) << "local time is the work done";
    EXPECT_EQ(w.systemc[i], w.local[i] / 100 * 100) << "SystemC time moves only at a quantum boundary, item " << i;
  }
  EXPECT_EQ(reg.values()["worker"]["busy_cycles"], 250) << "busy cycles do not depend on the quantum";
}

// Two readers that ran ahead by 30 and by 300 cycles block on fifos a writer fills at SystemC
// time 100: the first resumes at 100 (SystemC's time is later), the second keeps its 300.
struct Reader : Unit {
  sc_core::sc_fifo_in<int> in;
  std::uint64_t ahead, resumed_at = 0;
  SC_HAS_PROCESS(Reader);
  Reader(const sc_core::sc_module_name& n, stats::Registry& r, std::uint64_t a) : Unit(n, r), ahead(a) { SC_THREAD(run); }
  void run() {
    work(ahead);
    blocking([&] { return in.read(); });
    resumed_at = local_cycles();
  }
};

struct Writer : sc_core::sc_module {
  sc_core::sc_fifo_out<int> a, b;
  SC_HAS_PROCESS(Writer);
  explicit Writer(const sc_core::sc_module_name& n) : sc_core::sc_module(n) { SC_THREAD(run); }
  void run() {
    wait(cycles(100));
    a.write(1);
    b.write(2);
  }
};

TEST(QuantumTest, BlockedThreadResumesAtLaterTime) {
  install_report_handler();
  set_quantum_cycles(1000);
  stats::Registry reg;
  Reader behind("behind", reg, 30), ahead("ahead", reg, 300);
  Writer writer("writer");
  sc_core::sc_fifo<int> fa("fa", 1), fb("fb", 1);
  writer.a(fa), writer.b(fb);
  behind.in(fa), ahead.in(fb);
  sc_core::sc_start();
  EXPECT_EQ(behind.resumed_at, 100u) << "a thread behind SystemC time resumes at SystemC time";
  EXPECT_EQ(ahead.resumed_at, 300u) << "a thread ahead of SystemC time keeps its local time";
}

// The pipeline of SimTest.PipelineSpendsConfiguredCycles (producer -> DelayLine -> consumer):
// quantum 1 goes through the keepers but synchronises after every item, so it ends on the same
// cycle as the run without decoupling, which the expected value below spells out.
struct Producer : Unit {
  int batches;
  DelayLine<int> line;
  SC_HAS_PROCESS(Producer);
  Producer(const sc_core::sc_module_name& n, stats::Registry& r, int b) : Unit(n, r), batches(b), line("line", 4) {
    SC_THREAD(run);
  }
  void run() {
    for (int i = 0; i < batches; ++i) {
      work(batch_cycles(64, 16.0, 3));  // 4 + 3 cycles
      line.send(i, 5);                  // leaves 5 cycles later
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
      blocking([&] { return in.read(); });
      work(2);
      ++got;
    }
    done_at = local_cycles();
  }
};

TEST(QuantumTest, QuantumOneTimesAsNoDecoupling) {
  install_report_handler();
  set_quantum_cycles(1);
  stats::Registry reg;
  Producer p("producer", reg, 10);
  Consumer c("consumer", reg, 10);
  sc_core::sc_fifo<int> fifo("fifo", 2);
  p.line.out(fifo);
  c.in(fifo);
  sc_core::sc_start();
  EXPECT_EQ(c.got, 10);
  EXPECT_EQ(c.done_at, 10u * 7 + 5 + 2) << "ten batches of 7 cycles, the line's 5, then the last consume";
  EXPECT_EQ(reg.values()["producer"]["busy_cycles"], 70);
  EXPECT_EQ(reg.values()["consumer"]["busy_cycles"], 20);
}

}  // namespace
}  // namespace nbsim::sim
