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
# Every binary runs, failing or not (as cargo's --no-fail-fast), and the failures are named
# at the end.
# Each binary's wall time is printed, slowest last, so a CI log shows where the suite's
# minutes go (CI must stay under 40 of them).
failed=()
times=()
while read -r exe; do
  start=$SECONDS
  if ! FAKETIME_DONT_FAKE_MONOTONIC=1 faketime -f "$when" "$exe" --quiet; then
    failed+=("$(basename "$exe")")
  fi
  times+=("$((SECONDS - start)) $(basename "$exe")")
done < "$list"
echo "== seconds per test binary"
printf '%s\n' "${times[@]}" | sort -n | tail -15
if [ "${#failed[@]}" -gt 0 ]; then
  echo "test-future: ${#failed[@]} test binaries failed: ${failed[*]}" >&2
  exit 1
fi
