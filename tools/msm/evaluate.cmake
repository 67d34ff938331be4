# msm evaluate: the command and its CLI tests, kept apart from the other commands' file.
# Every test goes through msm_cli_test (tests/cli/expect: exit status and output together).
target_sources(msm_cli PRIVATE ${CMAKE_CURRENT_LIST_DIR}/evaluate.cpp)
target_link_libraries(msm_cli PUBLIC msm::evaluate_mpi)

if(MSM_BUILD_TESTS)
  set(MSM_EVALUATE_OUT ${CMAKE_CURRENT_BINARY_DIR}/evaluate-tests)
  set(MSM_EVALUATE_DATA ${PROJECT_SOURCE_DIR}/tests/data)
  # A small run: two built-in scenes at 32 x 32 texels, a 257-point grid, the named candidates and
  # 12 drawn sets of four functions (28 candidates).
  set(evaluate_small --scene fence,stair --shadow-size 32 --grid 257 --candidates named,sample:4:12 --fresh)

  msm_cli_test(msm_cli_evaluate_functions ARGS evaluate --functions
    OUTPUT "^z +z +power" "bump +exp\\(-8 \\(z - 1/2\\)\\^2\\) +other$")

  # One process, two threads (no mpirun): the reference table of the tests below.
  msm_cli_test(msm_cli_evaluate_single SETUP msm_evaluate_single
    ARGS evaluate ${evaluate_small} --threads 2 --out ${MSM_EVALUATE_OUT}/single
    OUTPUT "28 candidates \\(0 from the checkpoint\\) on 2 scene\\(s\\).*Wrote .*results.csv")
  foreach(file results.csv ranking.csv histogram.png summary.json)
    add_test(NAME msm_cli_evaluate_wrote_${file} COMMAND ${CMAKE_COMMAND} -E cat ${MSM_EVALUATE_OUT}/single/${file})
    set_tests_properties(msm_cli_evaluate_wrote_${file} PROPERTIES FIXTURES_REQUIRED msm_evaluate_single)
  endforeach()

  # Killed after 5 candidates (--stop-after ends the process at once with status 3, as a kill
  # would), then restarted from the checkpoint: the same table, bit for bit.
  msm_cli_test(msm_cli_evaluate_killed STATUS 3 SETUP msm_evaluate_killed
    ARGS evaluate ${evaluate_small} --threads 2 --stop-after 5 --out ${MSM_EVALUATE_OUT}/resumed)
  msm_cli_test(msm_cli_evaluate_resumed REQUIRES msm_evaluate_killed SETUP msm_evaluate_resumed
    ARGS evaluate --scene fence,stair --shadow-size 32 --grid 257 --candidates named,sample:4:12 --threads 1
      --out ${MSM_EVALUATE_OUT}/resumed
    OUTPUT "28 candidates \\(5 from the checkpoint\\)")
  add_test(NAME msm_cli_evaluate_resumed_equals_single
    COMMAND ${CMAKE_COMMAND} -E compare_files ${MSM_EVALUATE_OUT}/single/results.csv ${MSM_EVALUATE_OUT}/resumed/results.csv)
  set_tests_properties(msm_cli_evaluate_resumed_equals_single PROPERTIES
    FIXTURES_REQUIRED "msm_evaluate_single;msm_evaluate_resumed")

  # Two MPI ranks (CI runs as root: Open MPI needs its consent), one thread each: the same table.
  if(MSM_HAVE_MPI AND MPIEXEC_EXECUTABLE)
    set(mpi_two ${MPIEXEC_EXECUTABLE} ${MPIEXEC_NUMPROC_FLAG} 2 --oversubscribe)
    set(mpi_root OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1)
    msm_cli_test(msm_cli_evaluate_mpi SETUP msm_evaluate_mpi LAUNCHER ${mpi_two} ENVIRONMENT ${mpi_root}
      ARGS evaluate ${evaluate_small} --threads 1 --out ${MSM_EVALUATE_OUT}/mpi
      OUTPUT "28 candidates \\(0 from the checkpoint\\) on 2 scene\\(s\\) in [0-9.]+ s \\(2 rank\\(s\\)")
    add_test(NAME msm_cli_evaluate_mpi_equals_single
      COMMAND ${CMAKE_COMMAND} -E compare_files ${MSM_EVALUATE_OUT}/single/results.csv ${MSM_EVALUATE_OUT}/mpi/results.csv)
    set_tests_properties(msm_cli_evaluate_mpi_equals_single PROPERTIES
      FIXTURES_REQUIRED "msm_evaluate_single;msm_evaluate_mpi")
    # An error on the ranks (here: a bad candidate) ends them all with the message, no hang.
    msm_cli_test(msm_cli_evaluate_mpi_bad_candidate STATUS 2 LAUNCHER ${mpi_two} ENVIRONMENT ${mpi_root}
      ARGS evaluate --scene fence --shadow-size 16 --candidates z+nope --out ${MSM_EVALUATE_OUT}/bad
      OUTPUT "unknown function 'nope'" EMPTY ${MSM_EVALUATE_OUT}/bad)
    set_tests_properties(msm_cli_evaluate_mpi_bad_candidate PROPERTIES TIMEOUT 60)
  endif()

  # A checkpoint of another run is refused (unless --fresh).
  msm_cli_test(msm_cli_evaluate_other_checkpoint STATUS 2 REQUIRES msm_evaluate_single
    ARGS evaluate --scene fence --shadow-size 32 --grid 257 --candidates power4 --out ${MSM_EVALUATE_OUT}/single
    OUTPUT "the checkpoint belongs to a different run.*--fresh")

  # Bad input: a clear message and exit status 2.
  foreach(bad
      "unknown_function|--candidates z+z2+nope|unknown function 'nope'"
      "repeated_function|--candidates z+z2+z|the function 'z' appears twice, so the basis is linearly dependent \\(a singular moment space\\)"
      "dependent_on_grid|--candidates z+z2+z3+z4 --grid 4|linearly dependent on a grid of only 4 points \\(a singular moment space\\)"
      "bad_k|--candidates all:9|K = 9 is outside \\[1, 8\\]"
      "empty_stack|--scene ${MSM_EVALUATE_DATA}/evaluate_empty.json|the stack is empty"
      "unlit_stack|--scene ${MSM_EVALUATE_DATA}/evaluate_unlit.json|none receives light"
      "unknown_scene|--scene no-such-scene|no-such-scene: neither a built-in scene"
      "bad_grid|--grid 1|depth grid of 1 points is outside"
      "even_filter|--filter-size 8|filter of 8 taps"
      "unwritable_out|--out /proc/msm-evaluate/x|--out /proc/msm-evaluate/x: cannot create the directory")
    string(REPLACE "|" ";" parts "${bad}")
    list(GET parts 0 name)
    list(GET parts 1 args)
    list(GET parts 2 message)
    set(empty ${MSM_EVALUATE_OUT}/bad-${name})
    if(NOT args MATCHES "--out")
      string(APPEND args " --out ${empty}")
    else()
      set(empty "")
    endif()
    if(NOT args MATCHES "--scene")
      string(APPEND args " --scene fence")
    endif()
    if(NOT args MATCHES "--candidates")
      string(APPEND args " --candidates power2")
    endif()
    separate_arguments(args UNIX_COMMAND "${args} --shadow-size 16 --fresh")
    msm_cli_test(msm_cli_evaluate_${name} STATUS 2 ARGS evaluate ${args} OUTPUT "${message}" EMPTY ${empty})
  endforeach()

  # An imported mesh (glmark2-data's bunny, installed by scripts/bootstrap.sh, found at the
  # configured MSM_GLMARK2_MODELS_DIR): the scene is written with that path at configure time.
  configure_file(${MSM_EVALUATE_DATA}/evaluate_bunny.json.in ${MSM_EVALUATE_OUT}/evaluate_bunny.json @ONLY)
  msm_cli_test(msm_cli_evaluate_imported_mesh
    ARGS evaluate --scene ${MSM_EVALUATE_OUT}/evaluate_bunny.json --shadow-size 48 --grid 257
      --candidates power4,trig4,hamburger4 --fresh --out ${MSM_EVALUATE_OUT}/bunny
    OUTPUT "3 candidates \\(0 from the checkpoint\\) on 1 scene.*evaluate_bunny.json: [0-9]+ fragments \\([0-9]+ receive light")
endif()
