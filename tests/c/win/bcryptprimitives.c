/*
 * A stand-in for Windows' bcryptprimitives.dll, only for running the Windows build under wine.
 *
 * Rust's standard library (1.78 and later) draws random bytes (for HashMap keys) from
 * ProcessPrng in bcryptprimitives.dll, which every Windows 10 and 11 has. Wine 8 (Debian 12's
 * wine64) lacks that export, so a Rust DLL does not load under it. This DLL exports ProcessPrng
 * and forwards it to RtlGenRandom (advapi32's SystemFunction036), which wine has. The tests
 * build it with MinGW and place it beside the test program; it is never shipped in an FMU.
 */
#include <windows.h>

BOOLEAN WINAPI SystemFunction036(PVOID buffer, ULONG length); /* RtlGenRandom */

__declspec(dllexport) BOOL WINAPI ProcessPrng(PBYTE data, SIZE_T length) {
    while (length > 0) {
        ULONG n = length > 0x40000000 ? 0x40000000 : (ULONG)length;
        if (!SystemFunction036(data, n)) return FALSE;
        data += n;
        length -= n;
    }
    return TRUE;
}
