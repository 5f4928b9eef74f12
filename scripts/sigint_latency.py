#!/usr/bin/env python3
"""SIGINT latency of a reference render (issue 39 item 1).

Usage: scripts/sigint_latency.py ATMOS WIDTHxHEIGHT [DELAY_S]

Spawns `ATMOS render --model reference --view ground-noon --size WxH` with
SIGINT at its default action and unblocked (a CI or a shell's background job
may block or ignore it), waits until the render catches SIGINT (bit 2 of
SigCgt in /proc/PID/status: the driver's handler is installed), waits
DELAY_S more, sends SIGINT and prints the seconds until the process exits,
wall-clock and of CPU (user + system, all threads: the work it did after the
signal, which a loaded machine does not inflate).
"""
import os
import signal
import subprocess
import sys
import tempfile
import time


def main():
    atmos, size = sys.argv[1], sys.argv[2]
    delay = float(sys.argv[3]) if len(sys.argv) > 3 else 0.0

    def unblock():
        signal.signal(signal.SIGINT, signal.SIG_DFL)
        signal.pthread_sigmask(signal.SIG_SETMASK, [])

    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.time()
        p = subprocess.Popen([atmos, "render", "--model", "reference", "--view", "ground-noon",
                              "--size", size, "-q", "-o", os.path.join(tmp, "i.exr")],
                             preexec_fn=unblock, stderr=subprocess.PIPE, text=True)
        while p.poll() is None:
            with open(f"/proc/{p.pid}/status") as f:
                cgt = next(line for line in f if line.startswith("SigCgt:"))
            if (int(cgt.split()[1], 16) >> (signal.SIGINT - 1)) & 1:
                break
            time.sleep(0.002)
        t1 = time.time()
        time.sleep(delay)
        with open(f"/proc/{p.pid}/stat") as f:
            fields = f.read().rsplit(")", 1)[1].split()
        tick = os.sysconf("SC_CLK_TCK")
        cpu_before = (int(fields[11]) + int(fields[12])) / tick  # utime + stime
        t2 = time.time()
        p.send_signal(signal.SIGINT)
        err = p.stderr.read()
        _, status, usage = os.wait4(p.pid, 0)
        t3 = time.time()
        p.returncode = os.waitstatus_to_exitcode(status)
        cpu_after = usage.ru_utime + usage.ru_stime
    print(f"{size}: handler after {t1 - t0:.2f} s; SIGINT {delay:.1f} s later; exit "
          f"{p.returncode} {t3 - t2:.2f} s after it ({cpu_after - cpu_before:.2f} CPU s); "
          f"{err.strip()}")


if __name__ == "__main__":
    main()
