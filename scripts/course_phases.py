# Where the course's seven grading commands spend their time (issue 32): each command of
# scripts/time_course.sh run ROUNDS times as a separate `goldray mit6837` process at 800×800; per
# command the median of goldray's own `--stats-json` phases (load and build, render, write) and
# of the process's wall and processor time; "outside" is the wall time outside goldray's own
# total (starting the process, exiting it). Extra flags for every command go in EXTRA (e.g.
# EXTRA="--threads 1", for the parallel fraction).
#
#   python3 scripts/course_phases.py GOLDRAY_BINARY [ROUNDS]      # from the project root
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time

binary = os.path.realpath(sys.argv[1])
rounds = int(sys.argv[2]) if len(sys.argv) > 2 else 7
commands = [
    ("a01", "scene01_plane.txt", "8 18", ""),
    ("a02", "scene02_cube.txt", "8 18", ""),
    ("a03", "scene03_sphere.txt", "8 18", ""),
    ("a04", "scene04_axes.txt", "8 18", ""),
    ("a05", "scene05_bunny_200.txt", "0.8 1.0", ""),
    ("a06", "scene06_bunny_1k.txt", "8 18", "-bounces 4"),
    ("a07", "scene07_arch.txt", "8 18", "-bounces 4 -shadows"),
]
out = tempfile.mkdtemp()
os.chdir("cases/mit6837")
rows = []
for name, scene, depth, flags in commands:
    samples = []
    for _ in range(rounds):
        stats = os.path.join(out, "stats.json")
        argv = [binary, "mit6837", "-size", "800", "800", "-input", scene,
                "-output", f"{out}/{name}.png", "-normals", f"{out}/{name}n.png",
                "-depth", *depth.split(), f"{out}/{name}d.png", *flags.split(),
                "--quiet", "--stats-json", stats, *os.environ.get("EXTRA", "").split()]
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        start = time.perf_counter()
        subprocess.run(argv, check=True)
        wall = time.perf_counter() - start
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
        phases = json.load(open(stats))["seconds"]
        samples.append({
            "wall": wall, "processor": cpu, "outside": wall - phases["total"],
            "load": phases["parse"] + phases["build"], "render": phases["render"], "write": phases["write"],
        })
    rows.append((name, {k: statistics.median(s[k] for s in samples) for k in samples[0]}))
keys = ["wall", "processor", "outside", "load", "render", "write"]
print("command " + "".join(f"{k:>10}" for k in keys) + f"   (ms, medians of {rounds})")
for name, median in rows:
    print(f"{name:8}" + "".join(f"{1000 * median[k]:10.1f}" for k in keys))
print("all     " + "".join(f"{1000 * sum(m[k] for _, m in rows):10.1f}" for k in keys))
