# This technique's step of scripts/demo (sourced, in the registration list's order, with "$nbsim" the
# built nbsim, "$out" the demo's output folder, "$step" the step's number; run from the repository's
# root). A failure is reported and the demo goes on.
echo "== $step. Layered depth images: Table 1 and the parity test's accuracy (nbsim ldi table1)"
# Six shapes (the paper's sphere, a torus knot, nested shells with d = 6 and 18, coils) at five LDI
# sides, each peeled, cropped and compressed on llvmpipe, 4,096 test points and 4,096 uniform points
# classified by GL's parity test (both readers), the model's and the exact reference (about 20 s).
# Exit status 1: the readers, or GL and the model, disagree somewhere; the rest is still written.
"$nbsim" ldi table1 --sizes 64,128,256,512,1024 --out "$out/ldi" ||
  echo "ldi table1: the readers or GL and the model disagree, or a build failed (see above)"
# The LDI sample replayed by the model: its peel passes against GL's counters, its layers, crop and
# compressed texture against GL's, and its parity answers against GL's and the exact reference.
"$nbsim" compare traces/samples/ldi_nested_128.nbt || echo "ldi: the model's replay of the sample differs from GL's (see above)"
