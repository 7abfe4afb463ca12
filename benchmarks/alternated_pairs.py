#!/usr/bin/python3
"""Two builds of tlsph_bench compared in one run, as alternated pairs (the host's speed swings
30-40 % within minutes, so only runs side by side in time compare):

  /usr/bin/python3 benchmarks/alternated_pairs.py NAME_A BIN_A NAME_B BIN_B PAIRS CONFIG...

A CONFIG is threads:size:flavour; size 5312 (2,000 steps) or 41728 (200 steps); flavour
`defaults` (quadratic correction, Taylor quadrature), `linear` (linear correction, nodal) or
`jitter` (the defaults off the lattice by 1e-6 dx: no per-pair row shared). Each pair runs A then
B, the next B then A; printed per config: each build's median rate, the median of the pairs'
B/A ratios with every pair's, and the tip displacements both builds printed (equal physics)."""
import sys, subprocess, re, statistics, os
na, a, nb, b, pairs = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4], int(sys.argv[5])
configs = sys.argv[6:]
def args(size, flavour):
    x = ["--no-stream"]
    x += ["--steps", "2000"] if size == "5312" else ["--dx", "0.00625", "--steps", "200"]
    x += ["--correction", "linear", "--quadrature", "nodal"] if flavour == "linear" else ["--correction", "quadratic", "--quadrature", "taylor"]
    if flavour == "jitter": x += ["--jitter", "1e-6"]
    return x
def run(binary, threads, extra):
    env = dict(os.environ, OMP_NUM_THREADS=threads)
    out = subprocess.run([binary] + extra, capture_output=True, text=True, env=env).stdout
    rate = float(re.search(r"particle-steps/s ([0-9.e+-]+)", out).group(1))
    tip = re.search(r"tip u_z (\S+)", out).group(1)
    return rate, tip
for c in configs:
    threads, size, flavour = c.split(":")
    ra, rb, ratios = [], [], []
    tips = set()
    for p in range(pairs):
        order = [(a, ra), (b, rb)] if p % 2 == 0 else [(b, rb), (a, ra)]
        got = {}
        for binary, lst in order:
            r, tip = run(binary, threads, args(size, flavour)); lst.append(r); got[binary] = r; tips.add((binary == a, tip))
        ratios.append(got[b] / got[a])
    print(f"{c:22s} {na} median {statistics.median(ra):.3e}  {nb} median {statistics.median(rb):.3e}  "
          f"{nb}/{na} median of pair ratios {statistics.median(ratios):.3f} (pairs {' '.join(f'{x:.3f}' for x in ratios)})"
          f"  tips {sorted(tips)}", flush=True)
