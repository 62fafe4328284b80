// Mass and momentum conservation of the transfers, rigid translation and free flight on
// the CPU (checks in transfer_conservation_checks.h; the GPU twin is in tests/gpu/).
#include "transfer_conservation_checks.h"

int main()
{
  mpm_test::check_transfer_conservation<mpm_test::CpuTarget>();
  return mpm_test::finish("test_transfer_conservation");
}
