#!/usr/bin/env python3
"""The tables of docs/performance.md, made from measurements, never by hand.

    scripts/perf_table.py run [--bench build/bench] [--llvmpipe build/llvmpipe-render]
                              [--render build/render] [--before OLD/render]
                              [--threads 1,2] [--msaa 1,4] [--repeat 5] [--runs 3]
                              [--page docs/performance.md]
        runs `bench --json` (our frame times, in process) once for every thread
        count and sample count, and for each pair `bench --side-by-side
        LLVMPIPE RENDER` when the llvmpipe harness exists (the two executables
        alternately on the same files: the ratio), and `bench --side-by-side
        BEFORE RENDER` when --before names an older build; then writes the
        data and the tables into the page.

    scripts/perf_table.py table [--page docs/performance.md] [--check]
        rebuilds the tables from the data kept in the page; --check exits 1
        when the tables in the page are not the ones its data gives.

The page keeps the measurement itself (a JSON block between the markers
`perf-data begin` / `perf-data end`) and the tables made from it (between
`perf-table begin` / `perf-table end`); everything else on the page is prose.
"""
import argparse
import datetime
import json
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEFAULT_PAGE = os.path.join(ROOT, "docs", "performance.md")
TABLE_BEGIN, TABLE_END = "<!-- perf-table begin -->", "<!-- perf-table end -->"
DATA_BEGIN, DATA_END = "<!-- perf-data begin -->", "<!-- perf-data end -->"

# Workloads whose llvmpipe frame is not the same picture.
NOT_COMPARABLE = {"builtin": "its sky is image-based lighting, which llvmpipe-render does not draw"}

def side_by_side_entries(objects):
    """{workload: {...}} from `bench --side-by-side A B --json` (A = llvmpipe or the older build, B = ours)."""
    out = {}
    for o in objects:
        out[o["workload"]] = {
            "whole_a": o["whole_ms"]["a"], "whole_b": o["whole_ms"]["b"],
            "frame_a": o["frame_ms"]["a"], "frame_b": o["frame_ms"]["b"],
            "rounds": o["rounds"]["median"], "rounds_min": o["rounds"]["min"], "rounds_max": o["rounds"]["max"],
            "textures_a": o["textures_ms"]["a"], "textures_b": o["textures_ms"]["b"],
        }
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


def int_list(text):
    return [int(v) for v in text.split(",") if v]


def side_by_side(args, exe_a, threads, msaa):
    cmd = [args.bench, "--side-by-side", exe_a, args.render, "--threads", str(threads), "--msaa", str(msaa),
           "--runs", str(args.runs), "--repeat", str(args.repeat), "--json"]
    if args.workload:
        cmd[4:4] = ["--workload", args.workload]
    print("running:", " ".join(cmd), file=sys.stderr)
    return side_by_side_entries(json.loads(subprocess.run(cmd, capture_output=True, text=True, check=True).stdout))


def run(args):
    threads, msaa = int_list(args.threads), int_list(args.msaa)
    bench_cmd = [args.bench, "--threads", args.threads, "--msaa", args.msaa, "--repeat", str(args.repeat), "--json"]
    if args.workload:
        bench_cmd[1:1] = ["--workload", args.workload]
    data = {
        "date": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d"),
        "machine": machine(),
        "commit": commit(),
        "before": args.before or "",
        "threads": threads,
        "msaa": msaa,
        "repeat": args.repeat,
        "runs": args.runs,
    }
    print("running:", " ".join(bench_cmd), file=sys.stderr)
    data["bench"] = json.loads(subprocess.run(bench_cmd, capture_output=True, text=True, check=True).stdout)
    # 1 -> 2 threads, paired: frames of each thread count in turn, in one process.
    data["alternate"] = []
    if 1 in threads and 2 in threads:
        for s in msaa:
            alt_cmd = [args.bench, "--alternate", "--threads", "1,2", "--msaa", str(s), "--repeat", str(args.repeat),
                       "--json"]
            if args.workload:
                alt_cmd[1:1] = ["--workload", args.workload]
            print("running:", " ".join(alt_cmd), file=sys.stderr)
            data["alternate"] += json.loads(subprocess.run(alt_cmd, capture_output=True, text=True, check=True).stdout)
    have_llvmpipe = bool(args.llvmpipe) and os.access(args.llvmpipe, os.X_OK)
    if not have_llvmpipe:
        print(f"no llvmpipe harness at {args.llvmpipe}: the llvmpipe columns stay empty "
              "(configure with -DPRAST_LLVMPIPE=ON)", file=sys.stderr)
    data["side_by_side"] = []
    for t in threads:
        for s in msaa:
            entry = {"threads": t, "msaa": s, "llvmpipe": {}, "before": {}}
            if have_llvmpipe:
                entry["llvmpipe"] = side_by_side(args, args.llvmpipe, t, s)
            if args.before:
                entry["before"] = side_by_side(args, args.before, t, s)
            data["side_by_side"].append(entry)
    write_page(args.page, data)


def ratio_text(side):
    return f"**{side['rounds']:.2f}x** ({side['rounds_min']:.2f}-{side['rounds_max']:.2f})"


def table(data):
    """The Markdown tables of one measurement."""
    rep, runs = data["repeat"], data["runs"]
    sides = {(e["threads"], e["msaa"]): e for e in data["side_by_side"]}
    frames = {}
    rows = [
        "| workload | threads | samples | frame, median (min-max) | llvmpipe / ours | **ratio to llvmpipe** "
        "| before / ours | ratio to before | textures: llvmpipe / ours | whole process / frame |",
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    for r in data["bench"]:
        if r.get("alternate"):
            continue
        w, t, s = r["workload"], r["threads"], r["msaa"]
        f = r["frame_ms"]
        frames[(w, t, s)] = f["median"]
        entry = sides.get((t, s), {})
        ll = entry.get("llvmpipe", {}).get(w)
        before = entry.get("before", {}).get(w)
        frame = f"{f['median']:.1f} ms ({f['min']:.1f}-{f['max']:.1f})"
        if w in NOT_COMPARABLE:
            ll_frames, ll_ratio, textures = "-", f"- ({NOT_COMPARABLE[w]})", "-"
        elif ll:
            ll_frames = f"{ll['frame_a']:.1f} / {ll['frame_b']:.1f} ms"
            ll_ratio = ratio_text(ll)
            textures = (f"{ll['textures_a']:.0f} / {ll['textures_b']:.0f} ms"
                        if ll.get("textures_a", -1) >= 0 and ll.get("textures_b", 0) >= 1.0 else "-")
        else:
            ll_frames, ll_ratio, textures = "-", "-", "-"
        if before:
            b_frames, b_ratio = f"{before['frame_a']:.1f} / {before['frame_b']:.1f} ms", ratio_text(before)
        else:
            b_frames, b_ratio = "-", "-"
        mine = ll or before
        whole = f"{mine['whole_b'] / mine['frame_b']:.2f}" if mine and mine["frame_b"] > 0 else "-"
        rows.append(f"| `{w}` | {t} | {s} | {frame} | {ll_frames} | {ll_ratio} | {b_frames} | {b_ratio} "
                    f"| {textures} | {whole} |")
    out = "\n".join(rows) + "\n"
    # 1 -> 2 threads: ours from `bench --alternate` (paired frames in one
    # process); llvmpipe's from the side-by-side sets of each thread count,
    # which ran minutes apart.
    alternate = {(r["workload"], r["msaa"]): r for r in data.get("alternate", []) if r["threads"] == 2}
    if alternate:
        scale = ["", "| workload | samples | ours, 1 -> 2 threads (`bench --alternate`) | tile pass CPU time, 1 / 2 threads "
                 "| llvmpipe, 1 -> 2 threads (side by side) |", "| --- | --- | --- | --- | --- |"]
        one = {(r["workload"], r["msaa"]): r for r in data.get("alternate", []) if r["threads"] == 1}
        for (w, s), r in alternate.items():
            sp = r["speedup"]
            cpu = (f"{one[(w, s)]['tile_pass_cpu_ms']:.1f} / {r['tile_pass_cpu_ms']:.1f} ms" if (w, s) in one else "-")
            l1 = sides.get((1, s), {}).get("llvmpipe", {}).get(w)
            l2 = sides.get((2, s), {}).get("llvmpipe", {}).get(w)
            theirs = f"{l1['frame_a'] / l2['frame_a']:.2f}x" if l1 and l2 and w not in NOT_COMPARABLE else "-"
            scale.append(f"| `{w}` | {s} | **{sp['median']:.2f}x** ({sp['min']:.2f}-{sp['max']:.2f}) | {cpu} | {theirs} |")
        out += "\n".join(scale) + "\n"
    out += (f"\n{data['machine']}, {data['date']}, commit {data['commit']}; `--repeat {rep}`, `--runs {runs}`"
            + (f"; before = `{data['before']}`" if data.get("before") else "") + ".\n")
    return out


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
    r.add_argument("--before", default="", help="an older build's render, compared side by side too")
    r.add_argument("--workload", default="", help="a comma-separated list (default: all)")
    r.add_argument("--threads", default="1,2", help="thread counts, a comma-separated list")
    r.add_argument("--msaa", default="1,4", help="samples per pixel, a comma-separated list")
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
            print(f"perf_table.py: the tables in {args.page} are not the ones its data gives; "
                  "run scripts/perf_table.py table", file=sys.stderr)
            return 1
        return 0
    with open(args.page, "w") as f:
        f.write(text[:a] + want + text[b:])
    return 0


if __name__ == "__main__":
    sys.exit(main())
