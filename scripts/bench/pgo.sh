#!/usr/bin/env bash
# Pose-graph optimisation benchmark: traverse-pgo (SPA on CHOLMOD) against the Ceres reference
# (traverse-pgo-ceres) on the three graphs of ../shared/data/posegraphs, run one after the other on
# the same machine. Prints per graph both final chi2, their relative difference, both solve times
# [s] and the time ratio (Ceres / ours); the last line is one JSON object.
# Both solvers run single-threaded; wall time is the best of PGO_REPEATS runs, CPU time is reported
# too because the machine may be shared.
# Environment: TRAVERSE_BIN (default build/bin), PGO_REPEATS (runs per solver, best time; default
# 3), PGO_ARGS (extra arguments for traverse-pgo, e.g. "--config configs/pgo.yaml").
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
BIN="${TRAVERSE_BIN:-$ROOT/build/bin}"
DATA="$ROOT/../shared/data/posegraphs"
REPEATS="${PGO_REPEATS:-3}"
for exe in traverse-pgo traverse-pgo-ceres; do
  [[ -x $BIN/$exe ]] || { echo "missing $BIN/$exe (build first)" >&2; exit 1; }
done
TMP="$(mktemp -d)"
trap 'rm -rf "$TMP"' EXIT

for graph in input_M3500_g2o input_INTEL_g2o city10000; do
  for ((r = 0; r < REPEATS; r++)); do
    # shellcheck disable=SC2086
    "$BIN/traverse-pgo" "$DATA/$graph.g2o" ${PGO_ARGS:-} | tail -n 1 >>"$TMP/$graph.ours"
    "$BIN/traverse-pgo-ceres" "$DATA/$graph.g2o" | tail -n 1 >>"$TMP/$graph.ceres"
  done
done

python3 - "$TMP" "$REPEATS" <<'PY'
import json, os, sys
tmp, repeats = sys.argv[1], int(sys.argv[2])
rows = []
for graph in ["input_M3500_g2o", "input_INTEL_g2o", "city10000"]:
    runs = {}
    for solver in ["ours", "ceres"]:
        with open(os.path.join(tmp, f"{graph}.{solver}")) as f:
            runs[solver] = [json.loads(line) for line in f if line.strip()]
    ours = min(runs["ours"], key=lambda j: j["solve_s"])
    ceres = min(runs["ceres"], key=lambda j: j["solve_s"])
    rel = abs(ours["final_chi2"] - ceres["final_chi2"]) / ceres["final_chi2"]
    row = {
        "graph": graph, "vertices": ours["vertices"], "edges": ours["edges"],
        "initial_chi2_ours": ours["initial_chi2"], "initial_chi2_ceres": ceres["initial_chi2"],
        "final_chi2_ours": ours["final_chi2"], "final_chi2_ceres": ceres["final_chi2"],
        "final_chi2_rel_diff": rel,
        "converged_ours": ours["converged"], "converged_ceres": ceres["converged"],
        "iterations_ours": ours["iterations"], "iterations_ceres": ceres["iterations"],
        "solve_s_ours": ours["solve_s"], "solve_s_ceres": ceres["solve_s"],
        "time_ratio_ceres_over_ours": ceres["solve_s"] / ours["solve_s"],
        "solve_cpu_s_ours": ours["solve_cpu_s"], "solve_cpu_s_ceres": ceres["solve_cpu_s"],
        "cpu_ratio_ceres_over_ours": ceres["solve_cpu_s"] / ours["solve_cpu_s"],
        "marginals": ours["marginals"], "marginals_s": ours["marginals_s"],
    }
    rows.append(row)
    print(f"{graph}: {row['vertices']} vertices, {row['edges']} edges")
    print(f"  chi2 initial ours {row['initial_chi2_ours']:.6f}, ceres {row['initial_chi2_ceres']:.6f}")
    print(f"  chi2 final   ours {row['final_chi2_ours']:.6f}, ceres {row['final_chi2_ceres']:.6f}, "
          f"relative difference {100 * rel:.2e} %")
    print(f"  converged    ours {row['converged_ours']} ({row['iterations_ours']} iterations), "
          f"ceres {row['converged_ceres']} ({row['iterations_ceres']} iterations)")
    print(f"  solve        ours {row['solve_s_ours']:.3f} s, ceres {row['solve_s_ceres']:.3f} s, "
          f"ceres/ours {row['time_ratio_ceres_over_ours']:.2f}x (wall, best of {repeats})")
    print(f"  solve CPU    ours {row['solve_cpu_s_ours']:.3f} s, ceres {row['solve_cpu_s_ceres']:.3f} s, "
          f"ceres/ours {row['cpu_ratio_ceres_over_ours']:.2f}x")
    print(f"  marginals    {row['marginals']} poses in {row['marginals_s']:.3f} s")
summary = {
    "benchmark": "pgo", "cores": os.cpu_count(), "load_average_1min": os.getloadavg()[0],
    "repeats": repeats, "pgo_args": os.environ.get("PGO_ARGS", ""), "graphs": rows,
    "all_chi2_within_0.1_percent": all(r["final_chi2_rel_diff"] <= 1e-3 or
                                       r["final_chi2_ours"] <= r["final_chi2_ceres"] for r in rows),
    "all_converged": all(r["converged_ours"] and r["converged_ceres"] for r in rows),
    "ours_faster_on_all": all(r["solve_s_ours"] < r["solve_s_ceres"] for r in rows),
}
print(json.dumps(summary))
PY
