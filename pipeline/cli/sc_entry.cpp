// libsystemc.so ships a main() that calls sc_main(), so anything linking SystemC must define
// sc_main. nbsim has its own main() (the linker prefers it) and elaborates models itself, so this
// entry point is only reached if that ever changes: it says so instead of running nothing.
#include <cstdio>

extern "C" int sc_main(int, char*[]) {
  std::fprintf(stderr, "nbsim: internal error: SystemC's main() ran instead of nbsim's\n");
  return 1;
}
