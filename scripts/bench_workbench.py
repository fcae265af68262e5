#!/usr/bin/env python3
"""Issue 61's figures: the time from a workbench edit's POST to its answer (OUT rebuilt).

Usage: bench_workbench.py EDO_CITY TOWN WORK [ROUNDS]

Builds TOWN into WORK/out (release binary EDO_CITY), serves it with `--edit WORK/hyp.toml`,
then makes each edit of EDITS in turn, ROUNDS times (each round undoes its edits, so every
round starts from the same city), and prints the median time of each with the tiles it
rebuilt; WORK/serve.log has the server's line per rebuild, stage by stage. Standard
library only: `make bench` runs it beside the other benchmarks.
"""

import json
import shutil
import statistics
import subprocess
import sys
import time
import urllib.request
from pathlib import Path

# (what, route, body): the edits of BENCHMARKS.md's table, in its order.
EDITS = [
    ("one lot's type", "lot", {"lot": "5001", "field": "mtype", "value": "sangai"}),
    ("one lot's use", "lot", {"lot": "12001", "field": "use", "value": "buke"}),
    ("kura.gap = 2.5", "set", {"key": "kura.gap", "value": 2.5}),
    (
        "trees species mix",
        "set",
        {"key": "trees.species.default.sakura", "value": 5.0},
    ),
    ("trees.per_ha = 30", "set", {"key": "trees.per_ha", "value": 30.0}),
    ("seed", "reroll", {}),
]


def call(port, method, route, body=None, token=None):
    url = f"http://127.0.0.1:{port}{route}"
    data = None if body is None else json.dumps(body).encode()
    req = urllib.request.Request(url, data=data, method=method)
    req.add_header("Origin", f"http://127.0.0.1:{port}")
    if data is not None:
        req.add_header("Content-Type", "application/json")
    if token:
        req.add_header("X-Edo-City-Token", token)
    with urllib.request.urlopen(req, timeout=600) as r:
        return json.loads(r.read() or b"{}")


def main():
    exe, town, work = sys.argv[1], Path(sys.argv[2]), Path(sys.argv[3])
    rounds = int(sys.argv[4]) if len(sys.argv) > 4 else 3
    if work.exists():
        shutil.rmtree(work)
    work.mkdir(parents=True)
    out, hyp = work / "out", work / "hyp.toml"
    hyp.write_text("# the benchmark's hypothesis\n")
    subprocess.run(
        [exe, "build", town, "--out", out, "--params", hyp, "--quiet"], check=True
    )
    server = subprocess.Popen(
        [exe, "serve", out, "--edit", hyp, "--input", town, "--port", "0"],
        stdout=subprocess.PIPE,
        # Its line per rebuild, stage by stage.
        stderr=open(work / "serve.log", "w"),
        text=True,
    )
    try:
        port = None
        for line in server.stdout:
            if "http://127.0.0.1:" in line:
                port = int(line.split("http://127.0.0.1:")[1].split("/")[0])
                break
        if port is None:
            sys.exit("the server printed no address")
        while call(port, "GET", "/api/edit/status").get("busy"):
            time.sleep(0.2)
        token = call(port, "GET", "/api/token")["token"]
        times = {what: [] for what, _, _ in EDITS}
        tiles = {}
        for _ in range(rounds):
            for what, route, body in EDITS:
                t = time.perf_counter()
                done = call(port, "POST", f"/api/edit/{route}", body, token)
                times[what].append(time.perf_counter() - t)
                tiles[what] = len(done.get("changedTiles", []))
            for _ in EDITS:
                call(port, "POST", "/api/edit/undo", {}, token)
        print("| change | rebuilt tiles | POST to answer (median of %d) |" % rounds)
        print("|---|---|---|")
        for what, _, _ in EDITS:
            print(f"| {what} | {tiles[what]} | {statistics.median(times[what]):.2f} s |")
    finally:
        server.terminate()
        server.wait()


if __name__ == "__main__":
    main()
