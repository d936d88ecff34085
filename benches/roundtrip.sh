#!/usr/bin/env bash
# The round trip with LAMMPS on the peers' dense bed (10^4 grains, ../shared/peers):
#  1. LAMMPS pours the peers' recipe and write_data saves its bed (target/peers/lammps_bed.data);
#     grains reads it (benches/bench_bed_lammps.toml) and runs the throughput bench on it.
#  2. grains pours the same recipe (scenes/bench_bed.toml) and exports its bed
#     (target/peers/grains_bed.data); LAMMPS reads it (benches/lammps/readback.in) and runs.
# Each code also runs the other's bed and its own from the data file, NRUN steps each (data
# files hold no contact history: both codes restart every tangential spring at zero).
# Prints each code's contacts per grain on each bed: when read, and after running.
#
# usage: benches/roundtrip.sh        env: PEERS=path/to/peers  NRUN=2400 (the bench's 400 + 2000 steps)
# needs: apt install lammps python3; the first run settles LAMMPS' bed (7-15 min here) and
# pours grains' (about 5 min on 2 cores); both are cached under target/peers.
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
PEERS=${PEERS:-$ROOT/../shared/peers}
NRUN=${NRUN:-2400}
WORK=$ROOT/target/peers
command -v lmp >/dev/null || { echo "error: LAMMPS (lmp) is not installed; fix: apt install lammps" >&2; exit 1; }
[ -d "$PEERS/lammps" ] || { echo "error: no peer inputs in $PEERS; fix: set PEERS to the folder holding lammps/ and scene/" >&2; exit 1; }
mkdir -p "$WORK"
for d in lammps scene; do cp -r "$PEERS/$d" "$WORK/" && chmod -R u+w "$WORK/$d"; done
cargo build --release --quiet --manifest-path "$ROOT/Cargo.toml"
GRAINS=$ROOT/target/release/grains
cd "$ROOT"

echo "== 1. LAMMPS' bed into grains" >&2
bash "$WORK/lammps/run.sh" 10000 0 >/dev/null
lmp -in "$WORK/lammps/todata.in" -var rst "$WORK/work/lammps/10000/settled.rst" -var out "$WORK/lammps_bed.data" \
    -var dir "$WORK/lammps" -log "$WORK/log.todata" -screen none
# The bench runs warmup (work / N / 5) + work / N steps: NRUN in all.
WORK_PS=$(( NRUN * 10000 * 5 / 6 ))
bench_on() { "$GRAINS" bench --part throughput --sizes 10000 --threads 1 --precision f64 --repeats 1 --work "$WORK_PS" --bed "$1" --json; }
bench_on benches/bench_bed_lammps.toml > "$WORK/bench_on_lammps_bed.json"
readback() { lmp -in benches/lammps/readback.in -var data "$1" -var dir "$WORK/lammps" -var nrun "$NRUN" -log "$2" -screen none; }
readback "$WORK/lammps_bed.data" "$WORK/log.readback_own"

echo "== 2. grains' bed into LAMMPS" >&2
[ -f "$WORK/grains_bed/summary.json" ] || "$GRAINS" run scenes/bench_bed.toml --out "$WORK/grains_bed" >/dev/null
"$GRAINS" export "$WORK/grains_bed" --format lammps-data --out "$WORK/grains_bed.data" >&2
readback "$WORK/grains_bed.data" "$WORK/log.readback"
# grains on its own bed read back from the data file, as LAMMPS reads it.
sed 's|file = "../target/peers/lammps_bed.data"|file = "grains_bed.data"|' benches/bench_bed_lammps.toml > "$WORK/bench_bed_grains.toml"
bench_on "$WORK/bench_bed_grains.toml" > "$WORK/bench_on_grains_bed.json"

python3 - "$WORK" <<'PY'
import csv, json, sys
work = sys.argv[1]
def thermo(log):
    """(step, c_cavg) of every thermo row of a LAMMPS log."""
    rows, cols = [], None
    for line in open(log):
        w = line.split()
        if w[:1] == ["Step"]:
            cols = w
        elif cols and len(w) == len(cols) and w[0].isdigit():
            rows.append((int(w[0]), float(w[cols.index("c_cavg")])))
        elif w[:2] == ["Loop", "time"]:
            cols = None
    return rows
lammps_own = thermo(f"{work}/work/lammps/10000/log.settle")[-1]
stages = list(csv.DictReader(open(f"{work}/grains_bed/stages.csv")))
rows = [
    ("LAMMPS", "LAMMPS", f"{lammps_own[1]:.4f}", f"end of its pour (step {lammps_own[0]}, history kept)"),
    ("grains", "grains", f"{float(stages[-1]['coordination']):.4f}", f"end of its pour (t = {float(stages[-1]['time_s']):.3f} s)"),
]
for bed, file in (("LAMMPS", "lammps_bed.data"), ("grains", "grains_bed.data")):
    bench = json.load(open(f"{work}/bench_on_{bed.lower()}_bed.json"))
    t = bench["throughput"][0]
    log = "log.readback_own" if bed == "LAMMPS" else "log.readback"
    (s0, z0), (s1, z1) = thermo(f"{work}/{log}")[:2]
    rows += [
        (bed, "grains", f"{bench['bed']['coordination']:.4f}", f"read from {file}"),
        (bed, "LAMMPS", f"{z0:.4f}", f"read_data of {file}"),
        (bed, "grains", f"{t['contacts_per_grain']:.4f}", f"after {t['warmup_steps'] + t['steps']} steps"),
        (bed, "LAMMPS", f"{z1:.4f}", f"after {s1 - s0} steps"),
    ]
print(f"{'bed poured by':<14} {'code':<8} {'contacts/grain':>15}  when")
for bed, code, z, when in rows:
    print(f"{bed:<14} {code:<8} {z:>15}  {when}")
PY
