#!/bin/sh
# Regenerates tests/analysis/fixture/, the input folder of analysis/report.py's tests, from real nbsim
# outputs on the small samples (city_small_oq.nbt, and city_small_nb_reversed.nbt for a second trace
# in two sweeps) on four tiny particles captures, nine tiny shadows captures, a small `nbsim ldi table1` and ten tiny
# relief captures (five heightfields at two sizes) and the apps table of the OpenArena sample. Big files are
# trimmed to what the report reads.
# About a minute on 2 cores.
# Usage: tests/analysis/make_fixture.sh [NBSIM]   (default: build/pipeline/nbsim; run from anywhere)
set -eu
root=$(cd "$(dirname "$0")/../.." && pwd)
nbsim=$(realpath "${1:-$root/build/pipeline/nbsim}")
py=/usr/bin/python3
out=$root/tests/analysis/fixture
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$root"  # sweep files name traces relative to the repository

rm -rf "$out"
mkdir -p "$out/table2" "$out/sweeps"

# Table 1: the four build sizes (the file --json-out writes is one JSON array).
"$nbsim" bench nbuffer --only build --json-out "$out/table1.jsonl" >/dev/null

# Figure 4 at 32x32 (the demo uses 256x256: a 2.4 MB CSV).
"$nbsim" nbuffer coverage --size 32x32 --out "$tmp/figure4_map.png" >/dev/null
cp "$tmp/figure4_map.csv" "$out/figure4_map.csv"

# Table 2: table2.json plus each mode's run.json cut down to what the report reads.
"$nbsim" table2 traces/samples/city_small_oq.nbt --jobs 2 --json --out "$tmp/table2" >"$tmp/table2_rows.json"
$py - "$tmp/table2" "$out/table2" "$tmp/table2_rows.json" <<'EOF'
import json, os, sys
src, dst, rows = sys.argv[1:]
if os.path.exists(os.path.join(src, "table2.json")):
    table = json.load(open(os.path.join(src, "table2.json")))
else:  # an nbsim older than table2.json: rebuild it from --json
    version = json.load(open(os.path.join(src, "nb", "run.json")))["nbsim_version"]
    table = {"trace": "traces/samples/city_small_oq.nbt", "trace_crc32": "818900a2",
             "nbsim_version": version, "settings": [], "rows": json.load(open(rows))}
json.dump(table, open(os.path.join(dst, "table2.json"), "w"), indent=2)
for r in table["rows"]:
    run = json.load(open(os.path.join(src, r["mode"], "run.json")))
    keep = {k: run[k] for k in ("nbsim_version", "trace", "config", "summary", "frames") if k in run}
    os.makedirs(os.path.join(dst, r["mode"]))
    json.dump(keep, open(os.path.join(dst, r["mode"], "run.json"), "w"), indent=1)
EOF

# Sweeps: small.json and nbuffer_techniques.json as they are; nbuffer_resolution and fidelity on the two small samples only.
sweep() {  # name, sweep file
  "$nbsim" explore "$2" --jobs 2 --out "$tmp/sweeps/$1" >/dev/null
  mkdir -p "$out/sweeps/$1"
  cp "$tmp/sweeps/$1/results.csv" "$tmp/sweeps/$1/sweep.json" "$tmp/sweeps/$1/technique_results.json" "$out/sweeps/$1/"
}
small_traces() {  # sweep file -> the same sweep over the small samples, in $tmp
  $py - "$1" "$tmp/$(basename "$1")" <<'EOF'
import json, sys
s = json.load(open(sys.argv[1]))
s["traces"] = ["traces/samples/city_small_oq.nbt", "traces/samples/city_small_nb_reversed.nbt"]
json.dump(s, open(sys.argv[2], "w"), indent=2)
EOF
  echo "$tmp/$(basename "$1")"
}
sweep small pipeline/sweeps/small.json
sweep nbuffer_resolution "$(small_traces pipeline/sweeps/nbuffer_resolution.json)"
sweep fidelity "$(small_traces pipeline/sweeps/fidelity.json)"
# The report's leading section: one N-buffer design on every technique (the samples it names, about 20 s).
sweep nbuffer_techniques pipeline/sweeps/nbuffer_techniques.json

# Particles: four tiny captures (128x128, 4 frames, 2,000 sprites of 16 px), one per culling mode, and
# the table nbsim particles writes (particles.json alone: the replays' folders are not read).
mkdir -p "$out/particles"
(cd "$tmp" && for m in none center nb hiz; do
   "$nbsim" capture particles --size 128x128 --frames 4 --particles 2000 --sprite 16 --mode "$m" --levels-every 0 \
     -o "particles_$m.nbt" >/dev/null
 done &&
 "$nbsim" particles particles_none.nbt particles_center.nbt particles_nb.nbt particles_hiz.nbt --out particles >/dev/null)
cp "$tmp/particles/particles.json" "$out/particles/"

# Shadows: tiny captures (128x96, 2 frames, 64-lexel litmaps) of boxes, terrain and a small city in
# modes infinite, culled and clamped, and the table nbsim shadows writes (shadows.json alone).
mkdir -p "$out/shadows"
(cd "$tmp" && for s in boxes terrain city; do
   case $s in terrain) extra="--towers 8 --birds 120" ;; city) extra="--objects 400" ;; *) extra="" ;; esac
   for m in infinite culled clamped; do
     # shellcheck disable=SC2086
     "$nbsim" capture shadows --scene $s $extra --path fly --size 128x96 --frames 2 --litmap 64 --shadow-mode "$m" \
       -o "shadows_${s}_$m.nbt" >/dev/null
   done
 done &&
 "$nbsim" shadows shadows_*_*.nbt --out shadows >/dev/null)
cp "$tmp/shadows/shadows.json" "$out/shadows/"

# Layered depth images: Table 1 and the parity test's accuracy, two shapes at two small sides.
"$nbsim" ldi table1 --shapes sphere,nested:3 --sizes 32,64 --points 512 --out "$out/ldi" >/dev/null
rm -f "$out/ldi/ldi.csv"

# Relief textures: tiny captures (128x128, 4 frames: one per view angle) of each heightfield at 32 and 64 texels,
# and the table nbsim relief writes (relief.json alone: relief.csv and the replays' folders are not read).
# Their own folder, so that *.nbt is the ten relief traces alone (the rows name them as given: fbm_32.nbt ...).
mkdir -p "$out/relief" "$tmp/relief_traces"
(cd "$tmp/relief_traces" && for f in fbm walls spikes saddle step; do
   for n in 32 64; do
     "$nbsim" capture relief --scene boxes --boxes 0 --path fly --size 128x128 --frames 4 --field "$f" --field-size "$n" \
       --seed 5 -o "${f}_$n.nbt" >/dev/null
   done
 done &&
 "$nbsim" relief *.nbt --out "$tmp/relief" >/dev/null)
cp "$tmp/relief/relief.json" "$out/relief/"

# A real program's draw calls culled in every mode: the table of the OpenArena sample (table2.json alone).
mkdir -p "$out/apps"
"$nbsim" table2 traces/samples/apps_openarena_320.nbt --jobs 2 --out "$tmp/apps" >/dev/null
cp "$tmp/apps/table2.json" "$out/apps/"

du -sh "$out"
echo "wrote $out"
