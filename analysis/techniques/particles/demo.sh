# This technique's step of scripts/demo (sourced, in the registration list's order, with "$nbsim" the
# built nbsim, "$out" the demo's output folder, "$step" the step's number; run from the repository's
# root). A failure is reported and the demo goes on.
echo "== $step. Particles: depth tests per frame beside the paper's claim (traces/samples/particles_walk_256.nbt and the other modes)"
# The sample culls in mode nb; the model replays a trace in its capture's mode, so the other rows are
# captures of the same walk (scripts/make_samples' arguments, --mode aside; about 2 s on llvmpipe,
# kept in OUT/particles/traces and reused). A capture that fails leaves its row out.
ptraces=()
for m in none center nb hiz; do
  if [[ $m == nb ]]; then ptraces+=("traces/samples/particles_walk_256.nbt"); continue; fi
  t=$out/particles/traces/particles_walk_256_$m.nbt
  mkdir -p "$out/particles/traces"
  if [[ -f "$t" ]] || { "$nbsim" capture particles --scene city --size 256x256 --frames 16 --path walk --seed 1 \
       --particles 10000 --sprite 16 --mode "$m" -o "$t.part" > /dev/null && mv "$t.part" "$t"; }; then
    ptraces+=("$t")
  else
    echo "particles: the capture in mode $m failed (see above); its row is left out"
  fi
done
# Exit status non-zero: a replay failed or a trace is bad; the rest is still written.
"$nbsim" particles "${ptraces[@]}" --out "$out/particles" || echo "particles: a replay failed (see above)"
