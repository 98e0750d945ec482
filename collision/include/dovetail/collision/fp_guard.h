#pragma once
/// \file fp_guard.h
/// Stops the build if the compiler may rewrite floating-point arithmetic.
///
/// Why: a scenario's state hash is the same bits at any thread count and in
/// Debug and Release only because every operation rounds as written. The
/// top-level CMakeLists.txt refuses such flags in CMAKE_CXX_FLAGS; this
/// catches them whatever route they take (a target's options, CXXFLAGS in a
/// consumer project), for every file that uses the collision types.
/// -ffp-contract=off is set in dovetail_options; GCC and Clang define no macro
/// for contraction, so it is checked there, not here.

#if defined(__FAST_MATH__)
#error \
    "Dovetail must not be compiled with -ffast-math or -Ofast: results would depend on the optimiser"
#elif defined(__FINITE_MATH_ONLY__) && __FINITE_MATH_ONLY__
#error \
    "Dovetail must not be compiled with -ffinite-math-only: its NaN and infinity checks would be removed"
#elif defined(__ASSOCIATIVE_MATH__) || defined(__RECIPROCAL_MATH__)
#error \
    "Dovetail must not be compiled with -funsafe-math-optimizations, -fassociative-math or -freciprocal-math: results would depend on the optimiser"
#endif
