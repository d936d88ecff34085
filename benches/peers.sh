#!/usr/bin/env bash
# A peer, side by side: runs LAMMPS (and LIGGGHTS when installed) and `grains bench` on the
# same dense bed, one after the other, and prints grains' particle-steps per second over the
# peer's. The peers' inputs are those of ../shared/peers (the folder PEERS names), copied
# into target/peers so that their settled restarts and logs stay out of the shared folder.
#
# usage: benches/peers.sh [N=10000]        env: PEERS=path/to/peers  REPS=1  THREADS=1,2
# needs: apt install lammps [liggghts] time python3; the first run settles each peer's bed
# (about 15 min per code on this machine) and pours grains' bed (a few minutes), both cached.
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
N=${1:-10000}
PEERS=${PEERS:-$ROOT/../shared/peers}
REPS=${REPS:-1}
THREADS=${THREADS:-1,2}
WORK=$ROOT/target/peers
[ -d "$PEERS/lammps" ] || { echo "error: no peer inputs in $PEERS; fix: set PEERS to the folder holding lammps/ and scene/" >&2; exit 1; }
command -v lmp >/dev/null || { echo "error: LAMMPS (lmp) is not installed; fix: apt install lammps" >&2; exit 1; }
mkdir -p "$WORK"
for d in lammps liggghts scene; do
  [ -d "$PEERS/$d" ] && cp -r "$PEERS/$d" "$WORK/"
done
rm -f "$WORK/results/bench.csv"
codes=(lammps)
command -v liggghts >/dev/null && codes+=(liggghts)

cargo build --release --quiet --manifest-path "$ROOT/Cargo.toml"
for code in "${codes[@]}"; do
  echo "== $code, $N grains, $REPS timed run(s) (settles first if its bed is not cached)" >&2
  bash "$WORK/$code/run.sh" "$N" "$REPS" >/dev/null
done
echo "== grains bench, $N grains, threads $THREADS" >&2
"$ROOT/target/release/grains" bench --part throughput --sizes "$N" --threads "$THREADS" --precision f64,f32 --json > "$WORK/grains_bench.json"

python3 - "$WORK/results/bench.csv" "$WORK/grains_bench.json" <<'PY'
import csv, json, statistics, sys
rows = list(csv.DictReader(open(sys.argv[1])))
report = json.load(open(sys.argv[2]))
peers = {}
for r in rows:
    peers.setdefault(r["code"], []).append(r)
print(f"machine: {report['machine']['cpu']}, {report['machine']['cores']} cores")
print(f"{'code':<10} {'prec':<4} {'threads':>7} {'particle-steps/s':>17} {'contacts/grain':>15}   ratio to " + " / ".join(peers))
base = {code: statistics.median(float(r["psps"]) for r in rs) for code, rs in peers.items()}
for code, rs in peers.items():
    z = statistics.median(float(r["contacts_per_grain"]) for r in rs)
    print(f"{code:<10} {'f64':<4} {1:>7} {base[code]:>17.3e} {z:>15.3f}")
for t in report["throughput"]:
    ratios = " / ".join(f"{t['particle_steps_per_second'] / b:.2f}x" for b in base.values())
    print(f"{'grains':<10} {t['precision']:<4} {t['threads']:>7} {t['particle_steps_per_second']:>17.3e} {t['contacts_per_grain']:>15.3f}   {ratios}")
PY
