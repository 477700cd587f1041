# This technique's step of scripts/demo (sourced, in the registration list's order, with "$nbsim" the
# built nbsim, "$out" the demo's output folder, "$step" the step's number; run from the repository's
# root). A failure is reported and the demo goes on.
echo "== $step. Relief textures: every walk against GL and the exact reference (nbsim relief)"
# Five heightfields at four sizes, each seen at 0, 45, 80 and 89 degrees off the box's up axis at
# 128 x 128, every method (binary, exact, robust, robust_clamp, nbuffer) a box draw captured on
# llvmpipe, then replayed: per fragment the model's walk against GL's and the hit against the exact
# reference (about 12 s). Exit status 1: a walk differs from GL's somewhere; the rest is still written.
mkdir -p "$out/relief/traces"
rtraces=()
for f in fbm walls spikes saddle step; do
  for n in 32 64 128 256; do
    t="$out/relief/traces/${f}_$n.nbt"
    [[ -f "$t" ]] || "$nbsim" capture relief --size 128x128 --frames 4 --seed 5 --field "$f" \
      --field-size "$n" -o "$t" > /dev/null
    rtraces+=("$t")
  done
done
"$nbsim" relief "${rtraces[@]}" --out "$out/relief" | tail -32 || echo "relief: a walk differs from GL's or a replay failed (see above)"
"$nbsim" compare traces/samples/relief_fbm_64.nbt | tail -7 || echo "relief: the model's replay of the sample differs from GL's (see above)"
# The paper's Figure 12: the safety radius's allowed error against the robust searches' cost and hit
# error, on an fbm terrain (64², 128 x 128, the four view angles): the strict radius, then the
# paper's with the minimum and with the maximum over directions at each epsilon (about 10 s).
mkdir -p "$out/relief_figure12/traces"
ftraces=()
for spec in "strict" "paper min 0" "paper min 0.01" "paper min 0.02" "paper min 0.05" "paper min 0.1" \
            "paper max 0" "paper max 0.01" "paper max 0.02" "paper max 0.05" "paper max 0.1"; do
  read -r kind combine epsilon <<< "$spec"
  t="$out/relief_figure12/traces/fbm_64_${kind}_${combine:-all}_${epsilon:-0}.nbt"
  radius=(--radius strict)
  [[ $kind == paper ]] && radius=(--radius paper --radius-combine "$combine" --radius-epsilon "$epsilon")
  [[ -f "$t" ]] || "$nbsim" capture relief --size 128x128 --frames 4 --seed 5 --field fbm \
    --field-size 64 --methods exact,robust,robust_clamp "${radius[@]}" -o "$t" > /dev/null
  ftraces+=("$t")
done
"$nbsim" relief "${ftraces[@]}" --out "$out/relief_figure12" > /dev/null || echo "relief: a Figure 12 walk differs from GL's or a replay failed"
