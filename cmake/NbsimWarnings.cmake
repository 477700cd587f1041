# nbsim_target_defaults(<target>): C++20, warnings on our own code only, optional sanitizers.
# The warnings on nbsim's own code (also the interposer library's, which skips the rest below).
set(NBSIM_WARNING_OPTIONS -Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wno-sign-conversion)
function(nbsim_target_defaults target)
  target_compile_features(${target} PUBLIC cxx_std_20)
  set_target_properties(${target} PROPERTIES CXX_EXTENSIONS OFF)
  target_compile_options(${target} PRIVATE ${NBSIM_WARNING_OPTIONS})
  # a * b + c stays two roundings everywhere, even on -march builds with FMA hardware: Mesa's C and
  # JIT code round these products separately (the model's fused interpolation calls std::fma itself).
  target_compile_options(${target} PUBLIC -ffp-contract=off)
  if(NBSIM_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
  if(NBSIM_SANITIZE)
    target_compile_options(${target} PRIVATE -fsanitize=address,undefined,float-cast-overflow -fno-omit-frame-pointer)
    target_link_options(${target} PRIVATE -fsanitize=address,undefined,float-cast-overflow)
  endif()
  if(NBSIM_FUZZ)  # coverage for libFuzzer in every library the fuzz targets link (tests/fuzz)
    target_compile_options(${target} PRIVATE -fsanitize=fuzzer-no-link,address,undefined -fno-omit-frame-pointer
                                             -fno-sanitize-recover=undefined)
    target_link_options(${target} PRIVATE -fsanitize=address,undefined)
  endif()
endfunction()
