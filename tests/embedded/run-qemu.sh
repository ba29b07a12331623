#!/usr/bin/env bash
# Runs a bare-metal firmware ELF under qemu with semihosting and returns its exit status.
#   tests/embedded/run-qemu.sh MACHINE ELF [TIMEOUT_SECONDS]
#   MACHINE: mps2-an500 (Cortex-M7) | mps2-an386 (Cortex-M4F) | any qemu-system-arm -M name
# Semihosting output (SYS_WRITE0; qemu writes it to its stderr) and qemu's own messages are
# both sent to stdout, in order. Exit status: the firmware's
# SYS_EXIT_EXTENDED code (0 = pass); 124 on timeout; 125 on usage or setup errors.
# QEMU_SYSTEM_ARM overrides the qemu binary; QEMU_EXTRA_ARGS adds arguments (e.g. "-d in_asm").
set -u

if [[ $# -lt 2 || $# -gt 3 ]]; then
  echo "usage: $0 MACHINE ELF [TIMEOUT_SECONDS]" >&2
  exit 125
fi
machine=$1
elf=$2
timeout_s=${3:-60}
qemu=${QEMU_SYSTEM_ARM:-qemu-system-arm}

if [[ ! -f "$elf" ]]; then
  echo "run-qemu.sh: no such file: $elf" >&2
  exit 125
fi
if ! command -v "$qemu" >/dev/null 2>&1; then
  echo "run-qemu.sh: $qemu not found (apt-get install qemu-system-arm)" >&2
  exit 125
fi

# An image for the M7's FPv5 on the M4's FPv4-SP machine faults at its first double-precision
# instruction: refuse it up front when readelf can tell (ELF build attributes).
if [[ $machine == mps2-an386 || $machine == mps2-an385 ]] && command -v arm-none-eabi-readelf >/dev/null 2>&1; then
  if arm-none-eabi-readelf -A "$elf" 2>/dev/null | grep -q 'Tag_FP_arch: FPv5'; then
    echo "run-qemu.sh: $elf is built for an FPv5 (Cortex-M7) FPU; $machine has none: use mps2-an500" >&2
    exit 125
  fi
fi

# -nographic: no display, UART/monitor on stdio; stdin from /dev/null so that qemu neither
# waits for nor steals the caller's terminal input. -kernel loads the ELF by its load
# addresses; the M-profile core then takes SP and PC from the vector table at 0x0.
# shellcheck disable=SC2086
timeout -k 5 "$timeout_s" "$qemu" -M "$machine" -nographic \
  -semihosting-config enable=on,target=native -kernel "$elf" ${QEMU_EXTRA_ARGS:-} </dev/null 2>&1
rc=$?
if [[ $rc -eq 124 ]]; then
  echo "run-qemu.sh: TIMEOUT after ${timeout_s}s ($elf on $machine)" >&2
fi
exit $rc
