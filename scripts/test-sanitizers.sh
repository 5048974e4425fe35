#!/usr/bin/env bash
# Builds qsgi with AddressSanitizer and UndefinedBehaviorSanitizer (GCC, -DQSGI_SANITIZE=ON) in
# build-asan/ and runs the test suite there. Every sanitizer report aborts the process, so it fails
# the test that provoked it, including reports from the qsgi executable the CLI tests run.
# Extra arguments go to ctest (e.g. -R Cli).
#
# Left out here, and run in the Release suite (scripts/test.sh step 1): the statistical tests that
# trace millions of photons to bound a bias (or to compare with the reference renders) or 10^3-10^4
# frames to bound drift, or render every --quality level against them. Under the sanitizers they run 4-5x slower (the inside-corner test alone
# took 328 s on 2 cores) and repeat, millions of times over, code paths that the other tests take
# under the sanitizers too: tracing, every estimator and boundary rule, disc regions,
# incremental updates, the sweep and resume CLIs. Also left out: the glTF-Validator corpus
# (ValidatorCorpus), some 650 runs of the executable that would take minutes under the
# sanitizers; the same readers meet hostile bytes under them in the fuzzers (scripts/fuzz.sh) and
# in HostileInput.*, which run here. HostileInput's bad-file corpus runs only here when this stage
# runs (scripts/test.sh leaves it out of the release suite): the same assertions, and memory checked.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh --test
cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=Release -DQSGI_SANITIZE=ON -DQSGI_BUILD_BENCHMARKS=OFF
cmake --build build-asan
echo "test-sanitizers: setup and build took $SECONDS s" >&2
# Use of a stack frame after its function returned is looked for by the fuzzers (scripts/fuzz.sh),
# which feed the readers hostile bytes; here it would double the suite's time (ImpactCount's
# closed sphere: 10.3 s with it, 5.9 s without), for code that takes no input of its own.
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:strict_string_checks=1:detect_stack_use_after_return=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
cd build-asan
statistical='DetpBoundary\.(InsideCorner|OpenEdgeOfAFloor|OutsideOfASphere|FloorBesideABox|CeilingAboveALightPanel)'
statistical+='|Estimators\.(PaperRuleMatches|PlaneUnderPointLight|ClosedSphereGives|DetpAndPhotonMapAreIndependentOfTessellation)'
statistical+='|Incremental\.(NoDriftOverTenThousandFrames|RememberedCrossingsLeaveNoTraceAfterAThousandFrames)|Sweep\.TinyGrid|ReferenceAccuracy|GatherAccuracy|FinalGather\.ClosedSphere'
statistical+='|Sobol\.AgreesWith|QualityLevel\.EachLevelsErrorOnTheCommittedReferences'
statistical+='|Materials\.(AClosedSphereWithATexturedAlbedo|TheMaterialsRoomAgreesWith|EachFeatureAgreesWith)'
ctest --output-on-failure -j 2 -E "$statistical|ValidatorCorpus" "$@"
