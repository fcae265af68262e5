#!/usr/bin/env bash
# Runs every test binary of the suite under Debian's faketime on the first leap day at least a
# year and a day ahead (one pass is both: a later year and a 29 February), so a test that
# passes only on the day it was written fails here. This is how `make test` runs the suite:
# once, a year ahead (running it on today's date too doubled CI's time, to 67 minutes). rustc hangs
# under libfaketime, so the tests are built first and their executables run directly, from
# the crate root as cargo would. Doc tests need rustc and are left to `make test`.
set -euo pipefail
cd "$(dirname "$0")/.."
CARGO=${CARGO:-cargo}
list=$(mktemp)
trap 'rm -f "$list"' EXIT
$CARGO test --all-targets --no-run --message-format=json 2>/dev/null \
  | python3 -c '
import json, sys
for line in sys.stdin:
    try:
        m = json.loads(line)
    except ValueError:
        continue
    if m.get("reason") == "compiler-artifact" and m.get("executable") and m.get("profile", {}).get("test"):
        print(m["executable"])
' | sort -u > "$list"
n=$(wc -l < "$list")
if [ "$n" -eq 0 ]; then
  echo "test-future: no test executables were built" >&2
  exit 1
fi
when=$(python3 -c '
import datetime
ahead = datetime.date.today() + datetime.timedelta(days=366)
year = ahead.year
while True:
    try:
        leap = datetime.date(year, 2, 29)
        if leap >= ahead:
            break
    except ValueError:
        pass
    year += 1
print(f"@{leap} 12:00:00")
')
echo "== the suite under faketime '$when' ($n test binaries)"
# Every binary runs, failing or not (as cargo's --no-fail-fast), two at a time: one binary
# alone kept the two cores 1.1 busy (most tests drive the CLI, whose small builds leave a
# core idle), so the suite took twice the time it needs. Each binary's output is printed
# whole when it ends, its wall time with it; the slowest are listed at the end, so a CI log
# shows where the suite's minutes go (CI must stay under 40 of them), and the failures
# are named. The longest binaries start first: as the last run here measured them (kept in
# the target directory), else as they were when this was written (a hint for the order only).
# The binaries get the shell's PATH: a pyenv python puts its own bin first, and Blender's
# embedded python then takes pyenv's library for its own (no numpy: tests/crowd_clip.rs).
JOBS=${TEST_JOBS:-2} SUITE_PATH=$PATH python3 - "$list" "$when" <<'PY'
import os, subprocess, sys, time
from concurrent.futures import ThreadPoolExecutor

exes = [l.strip() for l in open(sys.argv[1]) if l.strip()]
when = sys.argv[2]
history = os.path.join(os.environ.get("CARGO_TARGET_DIR") or "target", "test-seconds.txt")
took = {name: 1000.0 - k for k, name in enumerate(
    ["real_data", "robustness", "workbench_reuse", "browser_workbench", "bad_input",
     "tiles", "cache_edits", "crowd_clip", "workbench", "trees", "kura", "cityjson"])}
try:
    for line in open(history):
        secs, name = line.split()
        took[name.rsplit("-", 1)[0]] = float(secs)
except (OSError, ValueError):
    pass
stem = lambda exe: os.path.basename(exe).rsplit("-", 1)[0]
exes.sort(key=lambda e: -took.get(stem(e), 0.0))
env = dict(os.environ, FAKETIME_DONT_FAKE_MONOTONIC="1", PATH=os.environ["SUITE_PATH"])

def run(exe):
    t = time.monotonic()
    p = subprocess.run(["faketime", "-f", when, exe, "--quiet"], env=env,
                       stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
    secs = time.monotonic() - t
    sys.stdout.write(f"== {os.path.basename(exe)} ({secs:.0f} s)\n")
    sys.stdout.write(p.stdout.decode(errors="replace"))
    sys.stdout.flush()
    return exe, secs, p.returncode

with ThreadPoolExecutor(max_workers=int(os.environ["JOBS"])) as pool:
    results = list(pool.map(run, exes))
print("== seconds per test binary, slowest last")
for exe, secs, _ in sorted(results, key=lambda r: r[1])[-15:]:
    print(f"{secs:6.0f} {os.path.basename(exe)}")
try:
    with open(history, "w") as f:
        f.writelines(f"{secs:.0f} {os.path.basename(exe)}\n" for exe, secs, _ in results)
except OSError:
    pass
failed = [os.path.basename(e) for e, _, code in results if code != 0]
if failed:
    print(f"test-future: {len(failed)} test binaries failed: {' '.join(failed)}", file=sys.stderr)
    sys.exit(1)
PY
