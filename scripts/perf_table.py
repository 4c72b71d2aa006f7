#!/usr/bin/env python3
"""The table of docs/performance.md, made from measurements, never by hand.

    scripts/perf_table.py run [--bench build/bench] [--llvmpipe build/llvmpipe-render]
                              [--render build/render] [--threads 2] [--msaa 1]
                              [--repeat 5] [--runs 3] [--page docs/performance.md]
        runs `bench --json` (our frame times, in process) and, when the
        llvmpipe harness exists, `bench --side-by-side LLVMPIPE RENDER` (the
        two executables alternately on the same files: the ratio), then
        writes the data and the table into the page.

    scripts/perf_table.py table [--page docs/performance.md] [--check]
        rebuilds the table from the data kept in the page; --check exits 1
        when the table in the page is not the one its data gives.

The page keeps the measurement itself (a JSON block between the markers
`perf-data begin` / `perf-data end`) and the table made from it (between
`perf-table begin` / `perf-table end`); everything else on the page is prose.
"""
import argparse
import datetime
import json
import os
import re
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEFAULT_PAGE = os.path.join(ROOT, "docs", "performance.md")
TABLE_BEGIN, TABLE_END = "<!-- perf-table begin -->", "<!-- perf-table end -->"
DATA_BEGIN, DATA_END = "<!-- perf-data begin -->", "<!-- perf-data end -->"

# Workloads whose llvmpipe frame is not the same picture.
NOT_COMPARABLE = {"builtin": "its sky is image-based lighting, which llvmpipe-render does not draw"}

# One line of `bench --side-by-side A B` per workload (tools/bench/bench.cpp).
SIDE_LINE = re.compile(
    r"^(?P<workload>\S+)\s+whole process A (?P<whole_a>[\d.]+) ms B (?P<whole_b>[\d.]+) ms .*?"
    r"\| frame median A (?P<frame_a>[\d.]+) ms B (?P<frame_b>[\d.]+) ms "
    r"\(A/B [\d.]+x; rounds (?P<rounds>[\d.]+)x, (?P<rounds_min>[\d.]+)x\.\.(?P<rounds_max>[\d.]+)x\)")


def parse_side_by_side(text):
    """{workload: {...}} from side-by-side output (A = llvmpipe, B = ours)."""
    out = {}
    for line in text.splitlines():
        m = SIDE_LINE.match(line)
        if m:
            d = {k: float(v) for k, v in m.groupdict().items() if k != "workload"}
            out[m.group("workload")] = d
    return out


def machine():
    model = "unknown CPU"
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    model = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    return f"{model}, {os.cpu_count()} cores, load {load:.1f}"


def commit():
    try:
        head = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True,
                              text=True, check=True).stdout.strip()
        dirty = subprocess.run(["git", "-C", ROOT, "status", "--porcelain", "--untracked-files=no"],
                               capture_output=True, text=True, check=True).stdout.strip()
        return head + (" with uncommitted changes" if dirty else "")
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def run(args):
    bench_cmd = [args.bench, "--threads", str(args.threads), "--msaa", str(args.msaa), "--repeat",
                 str(args.repeat), "--json"]
    if args.workload:
        bench_cmd[1:1] = ["--workload", args.workload]
    data = {
        "date": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d"),
        "machine": machine(),
        "commit": commit(),
        "threads": args.threads,
        "msaa": args.msaa,
        "repeat": args.repeat,
        "runs": args.runs,
    }
    print("running:", " ".join(bench_cmd), file=sys.stderr)
    data["bench"] = json.loads(subprocess.run(bench_cmd, capture_output=True, text=True, check=True).stdout)
    data["side_by_side"] = {}
    if args.llvmpipe and os.access(args.llvmpipe, os.X_OK):
        side_cmd = [args.bench, "--side-by-side", args.llvmpipe, args.render, "--threads", str(args.threads),
                    "--msaa", str(args.msaa), "--runs", str(args.runs), "--repeat", str(args.repeat)]
        if args.workload:
            side_cmd[4:4] = ["--workload", args.workload]
        print("running:", " ".join(side_cmd), file=sys.stderr)
        text = subprocess.run(side_cmd, capture_output=True, text=True, check=True).stdout
        data["side_by_side"] = parse_side_by_side(text)
    else:
        print(f"no llvmpipe harness at {args.llvmpipe}: the ratio column stays empty "
              "(configure with -DPRAST_LLVMPIPE=ON)", file=sys.stderr)
    write_page(args.page, data)


def table(data):
    """The Markdown table of one measurement."""
    t, s, rep, runs = data["threads"], data["msaa"], data["repeat"], data["runs"]
    rows = [
        "| workload | frame, median (min-max) | llvmpipe / ours, side by side | ratio to llvmpipe | threads | samples "
        "| machine | date | command |",
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    for r in data["bench"]:
        if r.get("alternate"):
            continue
        w = r["workload"]
        f = r["frame_ms"]
        frame = f"{f['median']:.1f} ms ({f['min']:.1f}-{f['max']:.1f})"
        cmd = f"`bench --workload {w} --threads {r['threads']} --msaa {r['msaa']} --repeat {rep} --json`"
        side = data["side_by_side"].get(w)
        if w in NOT_COMPARABLE:
            ll, ratio = "-", f"- ({NOT_COMPARABLE[w]})"
        elif side:
            ll = f"{side['frame_a']:.1f} / {side['frame_b']:.1f} ms"
            ratio = f"**{side['rounds']:.2f}x** ({side['rounds_min']:.2f}-{side['rounds_max']:.2f})"
            cmd += (f"<br>`bench --side-by-side build/llvmpipe-render build/render --workload {w} "
                    f"--threads {t} --msaa {s} --runs {runs} --repeat {rep}`")
        else:
            ll, ratio = "-", "-"
        rows.append(f"| `{w}` | {frame} | {ll} | {ratio} | {r['threads']} | {r['msaa']} | {data['machine']} "
                    f"| {data['date']} | {cmd} |")
    return "\n".join(rows) + "\n"


def between(text, begin, end):
    a, b = text.find(begin), text.find(end)
    if a < 0 or b < a:
        raise SystemExit(f"perf_table.py: the page has no {begin} ... {end} block")
    return a + len(begin), b


def write_page(page, data):
    with open(page) as f:
        text = f.read()
    a, b = between(text, DATA_BEGIN, DATA_END)
    text = text[:a] + "\n```json\n" + json.dumps(data, indent=1) + "\n```\n" + text[b:]
    a, b = between(text, TABLE_BEGIN, TABLE_END)
    text = text[:a] + "\n" + table(data) + text[b:]
    with open(page, "w") as f:
        f.write(text)


def read_data(text):
    a, b = between(text, DATA_BEGIN, DATA_END)
    block = text[a:b].strip()
    block = block.removeprefix("```json").removesuffix("```")
    return json.loads(block)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="mode", required=True)
    r = sub.add_parser("run", help="measure, then write the data and the table into the page")
    r.add_argument("--bench", default=os.path.join(ROOT, "build", "bench"))
    r.add_argument("--llvmpipe", default=os.path.join(ROOT, "build", "llvmpipe-render"))
    r.add_argument("--render", default=os.path.join(ROOT, "build", "render"))
    r.add_argument("--workload", default="", help="a comma-separated list (default: all)")
    r.add_argument("--threads", type=int, default=2)
    r.add_argument("--msaa", type=int, default=1)
    r.add_argument("--repeat", type=int, default=5)
    r.add_argument("--runs", type=int, default=3)
    r.add_argument("--page", default=DEFAULT_PAGE)
    t = sub.add_parser("table", help="rebuild the table from the data in the page")
    t.add_argument("--page", default=DEFAULT_PAGE)
    t.add_argument("--check", action="store_true", help="exit 1 when the page's table is not its data's")
    args = p.parse_args()
    if args.mode == "run":
        run(args)
        return 0
    with open(args.page) as f:
        text = f.read()
    data = read_data(text)
    a, b = between(text, TABLE_BEGIN, TABLE_END)
    want = "\n" + table(data)
    if args.check:
        if text[a:b] != want:
            print(f"perf_table.py: the table in {args.page} is not the one its data gives; "
                  "run scripts/perf_table.py table", file=sys.stderr)
            return 1
        return 0
    with open(args.page, "w") as f:
        f.write(text[:a] + want + text[b:])
    return 0


if __name__ == "__main__":
    sys.exit(main())
