// eicald: the real-time calibration service (work in progress on the walking skeleton).
#include <cstdio>

int main() {
  std::fprintf(stderr, "eicald: not built yet\n");
  return 1;
}
