# Read by ctest after the GoogleTest cases are discovered (tests/CMakeLists.txt): the COST of the
# tests that take longest, in seconds as they ran under `ctest -j 2` on the project's 2-core
# machine. With -j, ctest starts tests in descending cost; without these, a fresh build (as in
# CI, where no Testing/Temporary/CTestCostData.txt exists yet) starts them in declaration order,
# and one that starts near the end runs on alone while the other core idles. Only the order
# depends on these numbers (a name that no longer exists is ignored); once a build folder has run
# the suite, ctest's own measurements there take over. ValidatorCorpus.*, declared after this
# file is read, has its COST beside its add_test. Where a test was made cheaper without a new
# ctest -j 2 figure, its COST is the old one times the ratio of its CPU seconds measured after and
# before the change (GatherCache, Estimators and Cli's incremental test in the release suite);
# VertexFit's incremental test, missing here before, has its figures from the last full CI run.
if(QSGI_TESTS_SANITIZED)
  # scripts/test-sanitizers.sh (the statistical tests are not run there).
  set(costs
    ManyLights.AMillionLightsCoincidentAndPowerlessOnesRenderFinitely 27
    HostileInput.EveryBadFileIsRefusedWithOneLineNamingItExitTwoAndNothingWritten 85
    Estimators.IndexedPhotonMapAndDetpEqualBruteForce 50
    Cli.IncrementalRunWritesTheBytesOfAFullRecomputation 50
    Resume.RunKilledAtRandomMomentsResumesToTheBytesOfAnUninterruptedRun 40
    DiscRegions.TheStaticShortcutChangesNoDisc 35
    NumericalExtremes.SceneScaledByAThousandthOrAThousandGivesTheSameIrradiance 23
    PhotonMapUpdate.UpdatedMapEqualsNewMapAndBruteForce 21
    Resume.SigintAndSigtermStopAfterTheCurrentFrameWithAConsistentFolder 20
    GltfOut.KhronosSamplesComeBackWholeWithTheBake 19
    OwnSurface.TheTreeShortcutChangesNoStartPointOrDisc 18
    GatherCache.IncrementalFramesEqualFullRecomputationOnTheDataScenes 70
    VertexFit.IncrementalFramesEqualFullRecomputationOnTheDataScenes 75)
else()
  set(costs
    HostileInput.EveryBadFileIsRefusedWithOneLineNamingItExitTwoAndNothingWritten 95
    VertexFit.IncrementalFramesEqualFullRecomputationOnTheDataScenes 57
    GatherCache.IncrementalFramesEqualFullRecomputationOnTheDataScenes 29
    Estimators.IndexedPhotonMapAndDetpEqualBruteForce 38
    DetpBoundary.OutsideOfASphereIsUnbiasedWithinOnePercent 46
    GatherAccuracy.ErrorFallsWithGatherRaysAndPhotonsInEveryRegion 37
    Sobol.AgreesWithRandomWithinNoiseAndSpreadsLessUnderAPointLight 35
    Sweep.TinyGridTabulatesFallingErrorNoNonFiniteValuesAndResumesWithoutRecomputing 35
    Cli.IncrementalRunWritesTheBytesOfAFullRecomputation 26
    Incremental.NoDriftOverTenThousandFrames 28
    Sobol.AgreesWithRandomWithinNoiseForDirectionalSpotAndAreaLights 26
    Estimators.ClosedSphereGivesTwoWattsPerSquareMetreForEveryEstimator 20
    DiscRegions.TheStaticShortcutChangesNoDisc 17
    Resume.RunKilledAtRandomMomentsResumesToTheBytesOfAnUninterruptedRun 16
    DetpBoundary.CeilingAboveALightPanelSeesOnlyTheGap 16
    DetpBoundary.OpenEdgeOfAFloorIsUnbiased 15
    Estimators.PlaneUnderPointLightMatchesTheInverseSquareCosineLaw 15
    Cli.EveryEstimatorRendersEndToEnd 15
    DetpBoundary.FloorBesideABoxNeitherLosesNorGainsLightFromUnderIt 4
    Estimators.DetpAndPhotonMapAreIndependentOfTessellation 13
    GltfOut.ATransformFilesMotionBecomesTheAssetsNodeAnimation 12
    DiscRegions.PerFrameUpdatesEqualAFromScratchComputation 10
    GltfOut.KhronosSamplesComeBackWholeWithTheBake 10
    DetpBoundary.InsideCornerEdgesAreUnbiasedWithLinearAndFirstOrderWithClip 10)
endif()
while(costs)
  list(POP_FRONT costs name cost)
  set_tests_properties(${name} PROPERTIES COST ${cost})
endwhile()
