#!/usr/bin/python3
"""A distributed run is the serial run, bit for bit.

For each scene below (2D and 3D, covering the clamps' mirrored ghosts, moving clamps,
prescribed rotation, loads, gravity, probes, kinetic damping with the static stop, artificial
viscosity, the textbook and energy hourglass forms, the Taylor quadrature and the nodal one, a
body meshed by gmsh whose particles carry their quadrature moments),
`tlsph run` is run serially and under `mpirun -np R` (R given on the command line), and every
output file is compared:
  - the VTU frames: serially one .vtu per frame, on R > 1 ranks a .pvtu naming one piece per
    rank (NAME_NNNNNN/NAME_NNNNNN_R.vtu): the same points and arrays bit for bit, in particle
    order (through frame_dump), and the .pvd the same but for the extension; no frame files
    left that the .pvd does not list;
  - probes.csv / reactions.csv: byte for byte (comment lines aside);
  - energies.csv: byte for byte except the work books (external_work, boundary_work, damped,
    total, and hourglass for the textbook form), which are sums over the ranks' parts and may
    differ in the last bits: within 1e-12 of the row's largest book;
  - summary.json records the ranks, the same steps and outcome.
A restart from a checkpoint written on R ranks continues bit for bit, on R ranks and serially;
a run stopped by SIGTERM on R ranks continues bit for bit with --restart=latest; a set-up
error stops every rank with the serial message; a piece of a frame that cannot be written
stops every rank (exit 6) with that rank's reason; and a run that goes unstable stops at the
same step with the same frames. Exit status 0 when all agree.
Standard library only; run by ctest as mpi_distributed_R.
"""
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time

PROGRAM, MPIEXEC, RANKS, FRAME_DUMP = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4]
ENV = dict(os.environ, OMP_NUM_THREADS="1", OMPI_ALLOW_RUN_AS_ROOT="1",
           OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1", OMPI_MCA_btl_vader_single_copy_mechanism="none")

SCENES = {
    # 2D cantilever: mirrored clamp, gravity, a tip load, probes (kernel and nearest, stress),
    # kinetic damping to the static stop, Taylor quadrature, energy penalty.
    "beam2d": """
[scene]
dimension = 2
dx = 0.01
[material.steel]
model = neo-hookean
density = 1000
youngs_modulus = 1e6
poisson_ratio = 0.3
[body.beam]
shape = box
lower = 0 0
upper = 0.4 0.06
[clamp.root]
face = x-
[region.tip]
shape = box
lower = 0.39 0
upper = 0.41 0.06
[load.tip]
region = tip
type = force
value = 0 -2
ramp = 0.05
[gravity]
acceleration = 0 -9.81
[damping]
kinetic = true
[static]
enabled = true
tolerance = 1e-3
check_every = 20
[time]
end = 0.3
[output]
fields = displacement velocity von_mises flags
every_steps = 150
series_every_steps = 10
[probe.tip]
point = 0.4 0.03
quantities = displacement velocity cauchy_stress
[probe.root]
point = 0.05 0.0
method = nearest
""",
    # 3D plate: four mirrored clamps, a traction, nodal quadrature with the linear correction,
    # the textbook (Ganzenmueller) hourglass force, viscous damping.
    "plate3d": """
[scene]
dimension = 3
dx = 0.025
[material.plate]
model = saint-venant-kirchhoff
density = 1000
youngs_modulus = 1e7
poisson_ratio = 0.3
[body.plate]
shape = box
lower = 0 0 0
upper = 0.5 0.4 0.075
[clamp.left]
face = x-
[clamp.right]
face = x+
[clamp.front]
face = y-
[load.top]
face = z+
type = traction
value = 0 0 -1000
ramp = 0.002
[kernel]
correction = linear
[hourglass]
form = ganzenmueller
alpha = 2
[damping]
viscous = 50
[time]
end = 0.004
[output]
fields = displacement velocity J first_piola
every_steps = 100
series_every_steps = 10
[probe.centre]
point = 0.25 0.2 0.075
""",
    # 3D block: a clamp that rotates, a prescribed velocity region, artificial viscosity, an
    # initial spin, the energy penalty on the linear F with the quadratic correction.
    "block3d": """
[scene]
dimension = 3
dx = 0.02
[material.rubber]
model = neo-hookean
density = 1100
youngs_modulus = 5e5
poisson_ratio = 0.4
[body.block]
shape = box
lower = 0 0 0
upper = 0.3 0.12 0.1
[clamp.left]
face = x-
motion = rotation
axis = 1 0 0
point = 0 0.06 0.05
rate = 20
ramp = 0.005
[region.end]
shape = box
lower = 0.28 0 0
upper = 0.31 0.13 0.11
[prescribe.end]
region = end
motion = velocity
value = 0.2 0 0
ramp = 0.002
[initial.spin]
profile = rotation
axis = 0 0 1
point = 0.15 0.06 0.05
rate = 1
[hourglass]
gradient = linear
[artificial_viscosity]
linear = 0.5
quadratic = 1.0
[time]
end = 0.02
[output]
fields = displacement velocity cauchy_stress hourglass_error
every_steps = 80
series_every_steps = 10
hourglass_content = true
[probe.mid]
point = 0.15 0.06 0.05
quantities = displacement velocity
""",
    # 2D strip meshed by gmsh (shape = mesh): its particles carry their nodes' quadrature
    # moments into the Taylor term; a clamp on a named surface, gravity.
    "mesh2d": """
[scene]
dimension = 2
dx = 0.01
[material.rubber]
model = linear-elastic
density = 1000
youngs_modulus = 1e6
poisson_ratio = 0.3
[body.strip]
shape = mesh
file = strip.geo
[clamp.root]
surface = root
[gravity]
acceleration = 0 -9.81
[time]
end = 0.02
[output]
fields = displacement velocity
every_steps = 80
series_every_steps = 10
[probe.tip]
point = 0.2 0.02
quantities = displacement
""",
}

# Files the scenes read, written next to them.
FILES = {
    "strip.geo": """
Point(1) = {0, 0, 0};
Point(2) = {0.2, 0, 0};
Point(3) = {0.2, 0.04, 0};
Point(4) = {0, 0.04, 0};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Physical Curve("root") = {4};
Physical Surface("strip") = {1};
""",
}

BOOKS = {"external_work", "boundary_work", "damped", "total"}


def run(scene_file, directory, ranks, extra=()):
    command = [PROGRAM, "run", scene_file, "--output.directory=" + directory, "--overwrite",
               *extra]
    if ranks > 0:
        command = [MPIEXEC, "-np", str(ranks), "--oversubscribe", *command]
    result = subprocess.run(command, env=ENV, capture_output=True, text=True)
    return result.returncode, result.stdout + result.stderr


def data_lines(path):
    with open(path) as f:
        return [line.rstrip("\n") for line in f if not line.startswith("#")]


def compare_energies(a, b, books):
    la, lb = data_lines(a), data_lines(b)
    if len(la) != len(lb) or la[0] != lb[0]:
        return "energies.csv: different rows or header"
    header = la[0].split(",")
    for ra, rb in zip(la[1:], lb[1:]):
        va, vb = ra.split(","), rb.split(",")
        scale = max(abs(float(va[header.index(c)])) for c in books) or 1.0
        for name, x, y in zip(header, va, vb):
            if name in books:
                if abs(float(x) - float(y)) > 1e-12 * scale:
                    return f"energies.csv: {name} {x} vs {y}"
            elif x != y:
                return f"energies.csv: {name} {x} vs {y} (must be bitwise)"
    return None


def dump(frame):
    result = subprocess.run([FRAME_DUMP, frame], capture_output=True, text=True)
    return result.stdout if result.returncode == 0 else "unreadable: " + result.stderr


def frames_listed(directory):
    """Problems with the frame files of a run: a listed frame without its files (a .pvtu
    without all its pieces), or frame files the .pvd does not list."""
    pvds = [n for n in os.listdir(directory) if n.endswith(".pvd")]
    if len(pvds) != 1:
        return []
    stem = pvds[0][:-4]
    listed = re.findall(r'file="([^"]+)"', open(os.path.join(directory, pvds[0])).read())
    expected = set(listed) | {f[:-5] for f in listed if f.endswith(".pvtu")}
    problems = []
    if RANKS > 1 and not any(f.endswith(".pvtu") for f in listed):
        problems.append("no frame written in pieces")
    for name in listed:
        if name.endswith(".pvtu"):
            pieces = re.findall(r'Source="([^"]+)"', open(os.path.join(directory, name)).read())
            if len(pieces) != RANKS and RANKS > 1 or not all(
                    os.path.exists(os.path.join(directory, p)) for p in pieces):
                problems.append(f"{name}: pieces {pieces}")
    frame = re.escape(stem) + r"_\d{6}(\.p?vtu)?"
    present = {n for n in os.listdir(directory) if re.fullmatch(frame, n)}
    if present != expected:
        problems.append(f"frame files {sorted(present ^ expected)} not as the .pvd lists")
    return problems


def compare(serial, distributed, hourglass_book):
    problems = frames_listed(distributed)
    names = sorted(n for n in os.listdir(serial) if os.path.isfile(os.path.join(serial, n)))
    for name in names:
        a, b = os.path.join(serial, name), os.path.join(distributed, name)
        if re.fullmatch(r".*_\d{6}\.vtu", name) and not os.path.exists(b):
            pieces = b[:-4] + ".pvtu"
            if not os.path.exists(pieces):
                problems.append(name + " missing (neither .vtu nor .pvtu)")
            elif dump(a) != dump(pieces):
                problems.append(name + " differs from " + os.path.basename(pieces))
        elif name.endswith(".pvd"):
            same = os.path.exists(b) and (
                open(a).read() == open(b).read().replace('.pvtu"', '.vtu"'))
            if not same:
                problems.append(name + " differs (or missing)")
        elif not os.path.exists(b):
            problems.append(name + " missing")
        elif name == "summary.json":
            sa, sb = json.load(open(a)), json.load(open(b))
            if sb["ranks"] != RANKS or sa["ranks"] != 1:
                problems.append(f"summary.json: ranks {sa['ranks']} / {sb['ranks']}")
            for key in ("steps", "outcome", "simulated_time"):
                if sa[key] != sb[key]:
                    problems.append(f"summary.json: {key} {sa[key]} vs {sb[key]}")
        elif name == "energies.csv":
            books = BOOKS | ({"hourglass"} if hourglass_book else set())
            why = compare_energies(a, b, books)
            if why:
                problems.append(why)
        elif name.endswith(".csv"):
            if data_lines(a) != data_lines(b):
                problems.append(name + " differs")
        elif open(a, "rb").read() != open(b, "rb").read():
            problems.append(name + " differs")
    return problems


def continued(serial, distributed):
    """compare() for a run continued from a checkpoint (its summary.json counts only its part)."""
    return [p for p in compare(serial, distributed, False) if not p.startswith("summary.json")]


def report(what, problems, ok="identical"):
    """Prints one result line; 1 for a failure."""
    print(f"{what} on {RANKS} ranks: " + (ok if not problems else "; ".join(problems)))
    return int(bool(problems))


def main():
    work = tempfile.mkdtemp(prefix="tlsph_mpi_")
    failures = 0
    try:
        for name, text in FILES.items():
            with open(os.path.join(work, name), "w") as f:
                f.write(text)
        for name, text in SCENES.items():
            scene = os.path.join(work, name + ".ini")
            with open(scene, "w") as f:
                f.write(text)
            serial, distributed = os.path.join(work, name + "_1"), os.path.join(work, name + "_n")
            rc1, log1 = run(scene, serial, 0)
            rcn, logn = run(scene, distributed, RANKS)
            problems = []
            if rc1 != rcn:
                problems.append(f"exit status {rc1} serial, {rcn} on {RANKS} ranks:\n{logn}")
            if rc1 not in (0, 3):
                problems.append(f"serial run failed ({rc1}):\n{log1}")
            problems += compare(serial, distributed, "ganzenmueller" in text)
            failures += report(name, problems)

        # Restart: the checkpoint a run on RANKS ranks wrote at step 60, continued on RANKS
        # ranks (the output rewound to that step), ends where the serial run ends.
        scene = os.path.join(work, "block3d.ini")
        restarted = os.path.join(work, "restart_n")
        every = ["--checkpoint.every_steps=60"]
        rc, log = run(scene, restarted, RANKS, every)
        checkpoint = os.path.join(restarted, "checkpoints", "block3d_step000000060.ckpt")
        rc2, log2 = run(scene, restarted, RANKS, every + ["--restart=" + checkpoint])
        if "(step 60," not in log2:
            rc2 = -1
        problems = [] if os.path.exists(checkpoint) and rc == 0 and rc2 == 0 else [
            f"restart runs failed ({rc}, {rc2}):\n{log}\n{log2}"]
        if not problems:
            problems = continued(os.path.join(work, "block3d_1"), restarted)
        failures += report("restart", problems)

        # The same checkpoint continued serially: a checkpoint holds the whole state, so the
        # rank count may change at a restart.
        serial_restart = os.path.join(work, "restart_1")
        shutil.copytree(restarted, serial_restart)
        moved = os.path.join(serial_restart, "checkpoints", "block3d_step000000060.ckpt")
        rc3, log3 = run(scene, serial_restart, 0, every + ["--restart=" + moved])
        problems = [] if rc3 == 0 and "(step 60," in log3 else [f"serial restart failed:\n{log3}"]
        if not problems:
            problems = continued(os.path.join(work, "block3d_1"), serial_restart)
        failures += report("serial continuation of a checkpoint written", problems)

        # SIGTERM to mpirun (which passes it on to every rank): all ranks stop at one step,
        # a checkpoint is written, and --restart=latest ends where the serial run ends.
        # (The 3D block at a finer spacing: steps heavy enough that on 4 ranks sharing 2 cores
        # the run is not all waiting on messages.)
        stopped = os.path.join(work, "stopped_n")
        scene = os.path.join(work, "block3d.ini")
        slow = ["--scene.dx=0.01", "--time.end=0.3", "--output.every_steps=1000"]
        rc1, log1 = run(scene, os.path.join(work, "long_1"), 0, slow)
        command = [MPIEXEC, "-np", str(RANKS), "--oversubscribe", PROGRAM, "run", scene,
                   "--output.directory=" + stopped, "--overwrite", *slow] if RANKS > 0 else []
        process = subprocess.Popen(command, env=ENV, stdout=subprocess.PIPE,
                                   stderr=subprocess.STDOUT, text=True)
        # Once the run loop has started (its first frame is written), stop it.
        deadline = time.time() + 120
        while not os.path.exists(os.path.join(stopped, "block3d.pvd")) and time.time() < deadline:
            time.sleep(0.05)
        time.sleep(0.5)
        process.send_signal(signal.SIGTERM)
        out, _ = process.communicate(timeout=120)
        rc2, log2 = run(scene, stopped, RANKS, slow + ["--restart=latest"])
        problems = []
        if "stopped by signal 15" not in out or rc2 != 0 or rc1 != 0:
            problems.append(f"stop and restart failed ({rc1}, {rc2}):\n{out}\n{log2}")
        else:
            problems = continued(os.path.join(work, "long_1"), stopped)
        failures += report("SIGTERM and restart", problems)

        # A set-up error in one rank's particles (a particle without neighbours): every rank
        # stops with the serial run's message instead of waiting for the others.
        lone = os.path.join(work, "lone.ini")
        with open(lone, "w") as f:
            f.write(SCENES["beam2d"] + "\n[body.stray]\nshape = box\nlower = 1 1\nupper = 1.01 1.01\n")
        rc1, log1 = run(lone, os.path.join(work, "lone_1"), 0)
        rcn, logn = run(lone, os.path.join(work, "lone_n"), RANKS)
        first = lambda log: [l for l in log.splitlines() if "set-up error" in l]
        problems = [] if rc1 == 1 and rcn == 1 and first(log1) and first(log1) == first(logn) else [
            f"exit status {rc1} / {rcn}:\n{log1}\n{logn}"]
        failures += report("set-up error", problems, ok="same")

        # A following pressure reads the corners of its facets, which a rank may not hold: a
        # distributed run refuses it, naming the key.
        if RANKS > 1:
            with open(os.path.join(work, "strip_top.geo"), "w") as f:
                f.write(FILES["strip.geo"] + 'Physical Curve("top") = {3};\n')
            follow = os.path.join(work, "follow.ini")
            with open(follow, "w") as f:
                f.write(SCENES["mesh2d"].replace("file = strip.geo", "file = strip_top.geo") +
                        "[load.p]\nsurface = top\ntype = pressure\nvalue = 100\nfollow = true\n")
            rc, log = run(follow, os.path.join(work, "follow_n"), RANKS)
            expected = "[load.p] follow: a following pressure runs on one rank only"
            problems = [] if rc == 1 and expected in log else [f"exit status {rc}:\n{log}"]
            failures += report("following pressure", problems, ok="refused")

        # Pieces that cannot be written (a file where the first frame's directory of pieces
        # goes): every rank stops with exit 6 and the lowest failing rank's reason.
        if RANKS > 1:
            blocked = os.path.join(work, "blocked_n")
            os.makedirs(blocked)
            open(os.path.join(blocked, "block3d_000000"), "w").write("in the way")
            rc, log = run(os.path.join(work, "block3d.ini"), blocked, RANKS)
            piece = os.path.join(blocked, "block3d_000000", "block3d_000000_0.vtu")
            problems = [] if rc == 6 and "rank 0: cannot write VTU file " + piece in log else [
                f"exit status {rc}:\n{log}"]
            failures += report("failed piece write", problems, ok="stopped every rank")

        # An unstable run (a step 3x the rule's, uncapped): same step, cause and frames.
        scene = os.path.join(work, "beam2d.ini")
        unstable = ["--time.cfl=1.6", "--time.spectral_limit=false", "--damping.kinetic=false",
                    "--static.enabled=false", "--static.check_every=10"]
        rc1, log1 = run(scene, os.path.join(work, "unstable_1"), 0, unstable)
        rcn, logn = run(scene, os.path.join(work, "unstable_n"), RANKS, unstable)
        problems = []
        if rc1 != 4 or rcn != 4:
            problems.append(f"exit status {rc1} / {rcn}, expected 4:\n{log1}\n{logn}")
        else:
            problems = compare(os.path.join(work, "unstable_1"), os.path.join(work, "unstable_n"),
                               False)
            line1 = [l for l in log1.splitlines() if "unstable at step" in l]
            linen = [l for l in logn.splitlines() if "unstable at step" in l]
            if line1 != linen:
                problems.append(f"messages differ: {line1} / {linen}")
        failures += report("unstable run", problems)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
