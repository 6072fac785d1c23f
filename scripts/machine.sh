#!/bin/sh
# One line on the machine a test run ran on (CPU, its vector extensions, the system lavapipe), so that a failure
# that only some machines show (a driver crash) names the machine in the log.
cpu=$(grep -m1 'model name' /proc/cpuinfo 2>/dev/null | cut -d: -f2 | sed 's/^ //')
avx512=$(grep -qm1 avx512f /proc/cpuinfo 2>/dev/null && echo yes || echo no)
mesa=$(dpkg-query -W -f='${Version}' mesa-vulkan-drivers 2>/dev/null || echo unknown)
echo "machine: $(nproc) CPUs, ${cpu:-unknown CPU}, AVX-512 $avx512; mesa-vulkan-drivers $mesa; stack limit $(ulimit -s)"
