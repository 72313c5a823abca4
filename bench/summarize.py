#!/usr/bin/env python3
"""Turns papertear_bench's JSON (with repetitions) into the Markdown and JSON tables of
bench/README.md: medians per case, then the ratios papertear vs reference, 2 threads vs 1,
fracture pass vs step (on the quiet sheet, and while the default scene tears: the
fracture/default case's share_of_step counter), and measured vs the machine floor from the
probe cases; then the same step ratios as the step/paired cases measured them, pair by pair
within each iteration; and what the probes themselves gain from a second thread, the
ceiling for every 2 threads vs 1 ratio on the machine.

The floor of one RK4 step is the larger of (both are also reported on their own)
  compute: evaluated_springs * 4 stages / (sqrt+div pairs per second), and
  memory:  cells * bytes_per_cell * 4 stages / (triad bytes per second),
each at the same thread count (every spring the solver evaluates, distinct fine springs and
block springs, needs one square root and one division; every stage streams the solver state
at least once). Results without the evaluated_springs counter fall back to cells * 28.
Beside them, the spring floor: evaluated_springs * 4 / probe/spring's springs per second,
each spring costing what the fine-spring kernel's body costs with its data in L1 (loads,
arithmetic, stores; bench/probe_bench.cpp), and what that body costs against its sqrt+div
(probe/sqrt_div's rate / probe/spring's): how much of a "within N x of the compute floor"
budget the springs' own work takes before anything else in the step.

usage: summarize.py latest.json out.md out-summary.json
"""
import json
import re
import sys

NAME = re.compile(r"^(?P<family>[a-z_]+)/(?P<impl>[a-z_]+)(?:/(?P<size>\d+x\d+x\d+))?/threads:(?P<t>\d+)")


def load_medians(path):
    with open(path) as f:
        data = json.load(f)
    cases = {}
    for b in data["benchmarks"]:
        if b.get("aggregate_name", "median") != "median" or b.get("error_occurred"):
            continue
        name = re.sub(r"/iterations:\d+", "", b["run_name"].replace("/manual_time", ""))
        scale = {"ns": 1e-9, "us": 1e-6, "ms": 1e-3, "s": 1.0}[b["time_unit"]]
        counters = {k: v for k, v in b.items() if isinstance(v, (int, float)) and k not in (
            "real_time", "cpu_time", "iterations", "repetitions", "repetition_index", "threads",
            "family_index", "per_family_instance_index")}
        cases[name] = {"seconds": b["real_time"] * scale, "counters": counters, "label": b.get("label", "")}
    return data.get("context", {}), cases


def cells_of(size):
    nx, ny, nl = (int(v) for v in size.split("x"))
    return nx * ny * nl


# The default scene's sheet: the size in the names of the torn, fracture/default and render
# cases (bench_cases.cpp, default_scene_size).
DEFAULT_SIZE = "120x80x3"


def ratios(cases):
    out = []
    def get(name):
        return cases.get(name, {}).get("seconds")
    sizes = sorted({m.group("size") for n in cases if (m := NAME.match(n)) and m.group("size")}, key=cells_of)
    for size in sizes:
        ref = get(f"step/reference/{size}/threads:1")
        for t in (1, 2):
            pt = get(f"step/papertear/{size}/threads:{t}")
            if ref and pt:
                out.append((f"step {size}: reference (1 thread) / papertear ({t} threads)", ref / pt, "speed-up"))
        for family, impl in (("step", "papertear"), ("step", "torn"), ("force", "papertear"), ("fracture", "quiet")):
            one, two = get(f"{family}/{impl}/{size}/threads:1"), get(f"{family}/{impl}/{size}/threads:2")
            if one and two:
                out.append((f"{family}/{impl} {size}: 1 thread / 2 threads", one / two, "thread scaling"))
        for t in (1, 2):
            torn, quiet = get(f"step/torn/{size}/threads:{t}"), get(f"step/papertear/{size}/threads:{t}")
            if torn and quiet:
                out.append((f"step {size}, {t} threads: the default scene torn / the quiet sheet", torn / quiet, "torn"))
        for t in (1, 2):
            frac, step = get(f"fracture/quiet/{size}/threads:{t}"), get(f"step/papertear/{size}/threads:{t}")
            if frac and step:
                out.append((f"fracture pass / step {size}, {t} threads", frac / step, "share"))
            pairs = cases.get(f"probe/sqrt_div/threads:{t}", {}).get("counters", {}).get("pairs_per_s")
            bw = cases.get(f"probe/triad/threads:{t}", {}).get("counters", {}).get("bytes_per_s")
            step_case = cases.get(f"step/papertear/{size}/threads:{t}")
            if pairs and bw and step_case:
                cells = cells_of(size)
                springs = step_case["counters"].get("evaluated_springs", cells * 28)
                compute = springs * 4 / pairs
                memory = cells * step_case["counters"].get("bytes_per_cell", 0) * 4 / bw
                floor = max(compute, memory)
                out.append((f"step {size}, {t} threads: measured / floor ({floor * 1e3:.3f} ms, "
                            f"{'compute' if compute >= memory else 'memory'} bound)", step_case["seconds"] / floor, "vs floor"))
                # Issue 5 states its target against the compute floor alone.
                out.append((f"step {size}, {t} threads: measured / compute floor ({compute * 1e3:.3f} ms, sqrt+div)",
                            step_case["seconds"] / compute, "vs compute floor"))
                spring_rate = cases.get(f"probe/spring/threads:{t}", {}).get("counters", {}).get("springs_per_s")
                if spring_rate:
                    spring = springs * 4 / spring_rate
                    out.append((f"step {size}, {t} threads: measured / spring floor ({spring * 1e3:.3f} ms, "
                                "each spring at probe/spring's rate)", step_case["seconds"] / spring, "vs spring floor"))
        out += paired(cases, size)
    out += growth_and_render(cases)
    return out


def paired(cases, size):
    """The same ratios from step/paired (bench/paired_bench.cpp): each iteration times the
    reference, papertear on 2 and on 1 thread and the sqrt+div probe back to back, and the
    counters are medians of the per-iteration ratios, so drift of the machine's speed between
    cases does not enter them."""
    c = cases.get(f"step/paired/{size}/threads:2", {}).get("counters", {})
    rows = (("reference_over_t2", "reference (1 thread) / papertear (2 threads)", "speed-up"),
            ("reference_over_t1", "reference (1 thread) / papertear (1 thread)", "speed-up"),
            ("t1_over_t2", "papertear 1 thread / 2 threads", "thread scaling"),
            ("t2_over_compute_floor", "papertear (2 threads) / compute floor (sqrt+div)", "vs compute floor"))
    return [(f"step {size}, paired within each iteration: {what}", c[key], kind) for key, what, kind in rows if key in c]


def growth_and_render(cases):
    """Cost growth per cell-step against 90x90x5, and frames against the 150 ms target."""
    out = []
    def counter(name, key):
        return cases.get(name, {}).get("counters", {}).get(key)
    for t in (1, 2):
        base = counter(f"step/papertear/90x90x5/threads:{t}", "ns_per_cell_step")
        for size in ("300x300x5", "1000x1000x5"):
            big = counter(f"step/papertear/{size}/threads:{t}", "ns_per_cell_step")
            if base and big:
                out.append((f"ns per cell-step {size} / 90x90x5, {t} threads", big / base, "growth"))
    for t in (1, 2):
        share = counter(f"fracture/default/{DEFAULT_SIZE}/threads:{t}", "share_of_step")
        if share is not None:
            out.append((f"fracture pass / RK4 step while the default scene tears ({DEFAULT_SIZE}), {t} threads",
                        share, "share"))
    for cells in ("flat3", "flat10"):
        over = counter(f"stable_step/{cells}/90x90x5", "over_cube")
        if over is not None:
            out.append((f"stable step, {cells} cells / cube cells (90x90x5)", over, "stable step"))
    # What a second thread gives the probes (rates: FMA and sqrt+div share nothing between
    # threads, the triad only the memory system): the ceiling for the thread-scaling ratios
    # above, which on a VM can be well under 2 (a shared core, a lower clock with both cores
    # busy, other tenants).
    for probe, key in (("fma", "flops_per_s"), ("sqrt_div", "pairs_per_s"), ("spring", "springs_per_s"),
                       ("triad", "bytes_per_s")):
        one, two = counter(f"probe/{probe}/threads:1", key), counter(f"probe/{probe}/threads:2", key)
        if one and two:
            out.append((f"probe/{probe} ({key}): 2 threads / 1 thread", two / one, "thread scaling"))
    # A spring's whole cached work against its square root and division: the spring floor
    # over the compute floor, at any sheet size.
    for t in (1, 2):
        pairs, springs = counter(f"probe/sqrt_div/threads:{t}", "pairs_per_s"), counter(f"probe/spring/threads:{t}", "springs_per_s")
        if pairs and springs:
            out.append((f"probe/spring vs probe/sqrt_div, {t} threads: a spring's cached work / its sqrt+div",
                        pairs / springs, "vs compute floor"))
    for state in ("intact", "torn"):
        one = cases.get(f"render/frame/{state}/{DEFAULT_SIZE}/threads:1", {}).get("seconds")
        two = cases.get(f"render/frame/{state}/{DEFAULT_SIZE}/threads:2", {}).get("seconds")
        if two:
            out.append((f"render frame {state} 1280x720, 2 threads / 150 ms target", two / 0.150, "vs target"))
        if one and two:
            out.append((f"render/frame/{state}: 1 thread / 2 threads", one / two, "thread scaling"))
    return out


def fmt_time(s):
    return f"{s * 1e3:.3f} ms" if s >= 1e-3 else f"{s * 1e6:.1f} µs"


def fmt_counter(k, v):
    if k.endswith("_per_s"):
        for unit, scale in (("G", 1e9), ("M", 1e6), ("k", 1e3)):
            if v >= scale:
                return f"{k}={v / scale:.3g}{unit}/s"
    return f"{k}={v:.4g}"


def main(src, md_path, json_path):
    context, cases = load_medians(src)
    rows = ratios(cases)
    lines = ["# papertear benchmark results", "",
             f"Host `{context.get('host_name', '?')}`, {context.get('num_cpus', '?')} CPUs at "
             f"{context.get('mhz_per_cpu', '?')} MHz, load average {context.get('load_avg', '?')}, "
             f"{context.get('date', '?')}. Medians of the repetitions (wall time).", "",
             "| case | median | counters |", "| --- | --- | --- |"]
    for name, c in cases.items():
        counters = ", ".join(fmt_counter(k, v) for k, v in sorted(c["counters"].items()))
        label = f" `{c['label']}`" if c["label"] else ""
        lines.append(f"| `{name}` | {fmt_time(c['seconds'])} | {counters}{label} |")
    lines += ["", "| ratio | value |", "| --- | --- |"]
    lines += [f"| {what} | {value:.2f}{'×' if kind != 'share' else ''} |" if kind != "share"
              else f"| {what} | {value * 100:.1f} % |" for what, value, kind in rows]
    with open(md_path, "w") as f:
        f.write("\n".join(lines) + "\n")
    with open(json_path, "w") as f:
        json.dump({"context": context, "medians": cases,
                   "ratios": [{"what": w, "value": v, "kind": k} for w, v, k in rows]}, f, indent=1)


if __name__ == "__main__":
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    main(*sys.argv[1:])
