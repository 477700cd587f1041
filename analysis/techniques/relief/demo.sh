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
    [[ -f "$t" ]] || "$nbsim" capture relief --scene boxes --boxes 0 --path fly --size 128x128 --frames 4 --seed 5 --field "$f" \
      --field-size "$n" -o "$t" > /dev/null
    rtraces+=("$t")
  done
done
"$nbsim" relief "${rtraces[@]}" --out "$out/relief" | tail -32 || echo "relief: a walk differs from GL's or a replay failed (see above)"
"$nbsim" compare traces/samples/relief_fbm_64.nbt | tail -7 || echo "relief: the model's replay of the sample differs from GL's (see above)"
