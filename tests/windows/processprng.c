/* Stand-in bcryptprimitives.dll, for the Wine run of tests/windows/run.sh ONLY: never packaged.
 *
 * Why it exists: Rust's standard library on Windows imports ProcessPrng from
 * bcryptprimitives.dll (its source of random numbers, e.g. for HashMap keys). Every Windows 10
 * and later has that DLL, but Debian 12's Wine 8 does not, so without this file Wine refuses to
 * load GearRattle.dll. Placed next to the test program, it is found first in the DLL search
 * order. It forwards to RtlGenRandom (advapi32's SystemFunction036), which Wine has. */

#include <windows.h>

BOOLEAN WINAPI SystemFunction036(PVOID buffer, ULONG length); /* RtlGenRandom */

__declspec(dllexport) BOOL WINAPI ProcessPrng(PBYTE data, SIZE_T length) {
    while (length > 0) {
        ULONG chunk = length > 0x40000000 ? 0x40000000 : (ULONG)length;
        if (!SystemFunction036(data, chunk))
            return FALSE;
        data += chunk;
        length -= chunk;
    }
    return TRUE; /* like Windows' ProcessPrng, which always succeeds */
}
