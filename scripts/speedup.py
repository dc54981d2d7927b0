#!/usr/bin/python3
"""How much faster 2 ranks are than 1, measured in rounds on a noisy machine.

On the 2-core machines capstan is developed on, one build's run time varies by
10-30% from run to run, so one pair of runs says little about the 2-rank
speed-up. This script runs one case in rounds: each round runs 1 rank and 2
ranks with each partition (Mesh/Partition) back to back, the order rotated from
round to round, and the speed-up is taken within each round. It writes

    OUT/speedup.csv   one row per run
    OUT/speedup.md    each round's times and speed-ups, then per partition the
                      speed-ups' mean, median and range, and the speed-up of the
                      mean times, split into time per Krylov iteration and
                      Krylov iterations
    OUT/speedup.png   each round's speed-up per partition, with the target

    scripts/speedup.py [--out out/speedup] [--case G1] [--factor 8] [--rounds 3]
                       [--partitions METIS,Slabs] [--steps N] [--target 1.7]
                       [--capstan build/capstan] [--set PATH=VALUE]...

Runs are named OUT/<round>-<variant>, rounds a, b, c, ..., variants 1r, metis,
slabs; a run whose summary.json exists is reused (delete its folder to redo it),
so more rounds can be added later with a larger --rounds. G1 8x (the default)
takes 4-9 minutes on 2 ranks and 7-9 on 1 (docs/performance.md): a round of
three runs takes about 17 minutes.
"""
import argparse
import csv
import datetime
import os
import statistics

from capstan_runs import CAPSTAN, CASES, command, pyplot, summary, totals, write_report

ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
ap.add_argument("--out", default="out/speedup")
ap.add_argument("--capstan", default=CAPSTAN)
ap.add_argument("--case", default="G1", choices=sorted(CASES))
ap.add_argument("--factor", type=int, default=8, help="mesh refinement factor")
ap.add_argument("--rounds", type=int, default=3)
ap.add_argument("--partitions", default="METIS,Slabs", help="the 2-rank runs' Mesh/Partition values")
ap.add_argument("--steps", type=int, default=0, help="run only this many steps (0: the scene's)")
ap.add_argument("--target", type=float, default=1.7, help="the speed-up drawn as the target")
ap.add_argument("--set", action="append", default=[], metavar="PATH=VALUE",
                help="an extra scene parameter for every run (capstan run --set); repeatable")
args = ap.parse_args()

scene, base = CASES[args.case]
cells = [n * args.factor for n in base]
partitions = [p for p in args.partitions.split(",") if p]
variants = ["1r"] + [p.lower() for p in partitions]  # 1 rank, then 2 ranks per partition
rounds = [chr(ord("a") + k) for k in range(args.rounds)]

rows = []
for k, name in enumerate(rounds):
    order = variants[k % len(variants):] + variants[:k % len(variants)]  # each variant leads some round
    for v in order:
        ranks = 1 if v == "1r" else 2
        sets = list(args.set) + ([] if v == "1r" else [f"Mesh/Partition={partitions[variants.index(v) - 1]}"])
        out = os.path.join(args.out, f"{name}-{v}")
        s = summary(out, command(args.capstan, scene, out, cells, ranks, sets, args.steps), f"{name}-{v}",
                    "speedup.py")
        newton, linear, pstep = totals(s)
        rows.append({"round": name, "finished": datetime.datetime.fromtimestamp(
                         os.path.getmtime(os.path.join(out, "summary.json"))).isoformat(timespec="seconds"),
                     "variant": v, "ranks": ranks,
                     "partition": s["mesh"].get("partition", "METIS") if ranks > 1 else "",
                     "cut_faces": s["mesh"].get("cut_faces", ""), "dofs": s["mesh"]["dofs"],
                     "converged": s["converged"], "newton": newton, "linear": linear,
                     "pressure_step_linear": pstep, "total_s": round(s["timing"]["total"], 4),
                     "preconditioner_setup_s": round(s["timing"].get("preconditioner_setup", 0), 2),
                     "peak_mib_per_rank": round(s.get("memory", {}).get("peak_rss_mib_max", float("nan")), 1)})

os.makedirs(args.out, exist_ok=True)
with open(os.path.join(args.out, "speedup.csv"), "w", newline="") as fh:
    w = csv.DictWriter(fh, fieldnames=list(rows[0].keys()))
    w.writeheader()
    w.writerows(rows)

run = {(r["round"], r["variant"]): r for r in rows}
head = ["round", "order run"] + [f"{v} s" for v in variants] + [f"{v} speed-up" for v in variants[1:]]
lines = [f"{args.case} {'x'.join(map(str, cells))} ({rows[0]['dofs']} DOFs), "
         f"{'the first %d steps' % args.steps if args.steps else 'all steps'}; "
         f"speed-up = 1 rank's time / 2 ranks' time, within a round", "",
         "| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
speedups = {v: [] for v in variants[1:]}
for name in rounds:
    one = run[(name, "1r")]["total_s"]
    order = sorted(variants, key=lambda v: run[(name, v)]["finished"])  # as run (reused runs too)
    for v in variants[1:]:
        speedups[v].append(one / run[(name, v)]["total_s"])
    lines.append("| " + " | ".join([name, ", ".join(order)] + [f"{run[(name, v)]['total_s']:.1f}" for v in variants] +
                                   [f"{speedups[v][-1]:.2f}x" for v in variants[1:]]) + " |")
lines += [""]
mean = {v: statistics.mean(run[(n, v)]["total_s"] for n in rounds) for v in variants}
its = {v: statistics.mean(run[(n, v)]["linear"] for n in rounds) for v in variants}
for v in variants[1:]:
    x = speedups[v]
    per_it = (mean["1r"] / its["1r"]) / (mean[v] / its[v])
    lines.append(f"- {v}: speed-ups {', '.join(f'{s:.2f}x' for s in x)}; mean {statistics.mean(x):.2f}x, "
                 f"median {statistics.median(x):.2f}x, range {min(x):.2f}-{max(x):.2f}x; "
                 f"{sum(s >= args.target for s in x)} of {len(x)} rounds at or above {args.target}x. "
                 f"Of the mean times ({mean['1r']:.1f} s against {mean[v]:.1f} s): {mean['1r'] / mean[v]:.2f}x, "
                 f"per Krylov iteration {per_it:.2f}x, Krylov iterations {its[v] / its['1r']:.3f}x "
                 f"({its[v]:.0f} against {its['1r']:.0f})")
write_report(os.path.join(args.out, "speedup.md"), lines)
plt = pyplot()

fig, ax = plt.subplots(figsize=(7, 4))
for v, marker in zip(variants[1:], "os^v"):
    ax.plot(rounds, speedups[v], marker + "-", label=f"2 ranks, {v} (mean {statistics.mean(speedups[v]):.2f}x)")
ax.axhline(args.target, color="gray", ls=":", label=f"target {args.target}x")
ax.axhline(2.0, color="lightgray", ls="--", label="ideal 2x")
ax.set_xlabel("round (runs back to back)")
ax.set_ylabel("speed-up over 1 rank")
ax.set_title(f"{args.case} {'x'.join(map(str, cells))}: 2 ranks against 1, round by round")
ax.set_ylim(1.0, max(2.1, max(max(x) for x in speedups.values()) + 0.05))
ax.grid(True, alpha=0.3)
ax.legend(fontsize=8)
fig.tight_layout()
fig.savefig(os.path.join(args.out, "speedup.png"), dpi=120)
print(f"wrote {args.out}/speedup.csv, speedup.md, speedup.png")
