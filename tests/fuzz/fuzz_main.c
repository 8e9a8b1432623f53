/* fuzz_main.c: the libFuzzer entry point of one target, chosen at build time
 * (-DPD_FUZZ_TARGET=pd_fuzz_off, ...; make fuzz). An answer that is not
 * well-formed traps, so libFuzzer keeps the input as a crash. */
#include "fuzz_targets.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (!PD_FUZZ_TARGET(data, size))
        __builtin_trap();
    return 0;
}
