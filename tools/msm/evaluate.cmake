# msm evaluate (issue 16): the command and its CLI tests, kept apart from the other commands' file.
target_sources(msm PRIVATE ${CMAKE_CURRENT_LIST_DIR}/evaluate.cpp)
target_link_libraries(msm PRIVATE msm::evaluate_mpi)

if(MSM_BUILD_TESTS)
  set(MSM_EVALUATE_OUT ${CMAKE_CURRENT_BINARY_DIR}/evaluate-tests)
  set(MSM_EVALUATE_DATA ${PROJECT_SOURCE_DIR}/tests/data)
  # A small run: two built-in scenes at 32 x 32 texels, a 257-point grid, the named candidates and
  # 12 drawn sets of four functions (28 candidates).
  set(evaluate_small --scene fence,stair --size 32 --grid 257 --candidates named,sample:4:12 --fresh)

  add_test(NAME msm_cli_evaluate_functions COMMAND msm evaluate --functions)
  set_tests_properties(msm_cli_evaluate_functions PROPERTIES
    PASS_REGULAR_EXPRESSION "^z +z +power\n.*\nbump +exp\\(-8 \\(z - 1/2\\)\\^2\\) +other\n$")

  # One process, two threads (no mpirun): the reference table of the tests below.
  add_test(NAME msm_cli_evaluate_single COMMAND msm evaluate ${evaluate_small} --threads 2 --out ${MSM_EVALUATE_OUT}/single)
  set_tests_properties(msm_cli_evaluate_single PROPERTIES FIXTURES_SETUP msm_evaluate_single
    PASS_REGULAR_EXPRESSION "28 candidates \\(0 from the checkpoint\\) on 2 scene\\(s\\).*Wrote .*results.csv")
  foreach(file results.csv ranking.csv histogram.png summary.json)
    add_test(NAME msm_cli_evaluate_wrote_${file} COMMAND ${CMAKE_COMMAND} -E cat ${MSM_EVALUATE_OUT}/single/${file})
    set_tests_properties(msm_cli_evaluate_wrote_${file} PROPERTIES FIXTURES_REQUIRED msm_evaluate_single)
  endforeach()

  # Killed after 5 candidates (--stop-after ends the process at once, as a kill would), then
  # restarted from the checkpoint: the same table, bit for bit.
  add_test(NAME msm_cli_evaluate_killed
    COMMAND msm evaluate ${evaluate_small} --threads 2 --stop-after 5 --out ${MSM_EVALUATE_OUT}/resumed)
  set_tests_properties(msm_cli_evaluate_killed PROPERTIES FIXTURES_SETUP msm_evaluate_killed WILL_FAIL TRUE)
  add_test(NAME msm_cli_evaluate_resumed
    COMMAND msm evaluate --scene fence,stair --size 32 --grid 257 --candidates named,sample:4:12 --threads 1
      --out ${MSM_EVALUATE_OUT}/resumed)
  set_tests_properties(msm_cli_evaluate_resumed PROPERTIES FIXTURES_REQUIRED msm_evaluate_killed
    FIXTURES_SETUP msm_evaluate_resumed PASS_REGULAR_EXPRESSION "28 candidates \\(5 from the checkpoint\\)")
  add_test(NAME msm_cli_evaluate_resumed_equals_single
    COMMAND ${CMAKE_COMMAND} -E compare_files ${MSM_EVALUATE_OUT}/single/results.csv ${MSM_EVALUATE_OUT}/resumed/results.csv)
  set_tests_properties(msm_cli_evaluate_resumed_equals_single PROPERTIES
    FIXTURES_REQUIRED "msm_evaluate_single;msm_evaluate_resumed")

  # Two MPI ranks (CI runs as root: Open MPI needs its consent), one thread each: the same table.
  if(MSM_HAVE_MPI AND MPIEXEC_EXECUTABLE)
    add_test(NAME msm_cli_evaluate_mpi
      COMMAND ${MPIEXEC_EXECUTABLE} ${MPIEXEC_NUMPROC_FLAG} 2 --oversubscribe $<TARGET_FILE:msm> evaluate
        ${evaluate_small} --threads 1 --out ${MSM_EVALUATE_OUT}/mpi)
    set_tests_properties(msm_cli_evaluate_mpi PROPERTIES FIXTURES_SETUP msm_evaluate_mpi
      ENVIRONMENT "OMPI_ALLOW_RUN_AS_ROOT=1;OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1"
      PASS_REGULAR_EXPRESSION "28 candidates \\(0 from the checkpoint\\) on 2 scene\\(s\\) in [0-9.]+ s \\(2 rank\\(s\\)")
    add_test(NAME msm_cli_evaluate_mpi_equals_single
      COMMAND ${CMAKE_COMMAND} -E compare_files ${MSM_EVALUATE_OUT}/single/results.csv ${MSM_EVALUATE_OUT}/mpi/results.csv)
    set_tests_properties(msm_cli_evaluate_mpi_equals_single PROPERTIES
      FIXTURES_REQUIRED "msm_evaluate_single;msm_evaluate_mpi")
    # An error on the ranks (here: a bad candidate) ends them all with the message, no hang.
    add_test(NAME msm_cli_evaluate_mpi_bad_candidate
      COMMAND ${MPIEXEC_EXECUTABLE} ${MPIEXEC_NUMPROC_FLAG} 2 --oversubscribe $<TARGET_FILE:msm> evaluate
        --scene fence --size 16 --candidates z+nope --out ${MSM_EVALUATE_OUT}/bad)
    set_tests_properties(msm_cli_evaluate_mpi_bad_candidate PROPERTIES TIMEOUT 60
      ENVIRONMENT "OMPI_ALLOW_RUN_AS_ROOT=1;OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1"
      PASS_REGULAR_EXPRESSION "unknown function 'nope'")
    add_test(NAME msm_cli_evaluate_mpi_bad_candidate_status
      COMMAND ${MPIEXEC_EXECUTABLE} ${MPIEXEC_NUMPROC_FLAG} 2 --oversubscribe $<TARGET_FILE:msm> evaluate
        --scene fence --size 16 --candidates z+nope --out ${MSM_EVALUATE_OUT}/bad)
    set_tests_properties(msm_cli_evaluate_mpi_bad_candidate_status PROPERTIES TIMEOUT 60 WILL_FAIL TRUE
      ENVIRONMENT "OMPI_ALLOW_RUN_AS_ROOT=1;OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1")
  endif()

  # A checkpoint of another run is refused (unless --fresh).
  add_test(NAME msm_cli_evaluate_other_checkpoint
    COMMAND msm evaluate --scene fence --size 32 --grid 257 --candidates power4 --out ${MSM_EVALUATE_OUT}/single)
  set_tests_properties(msm_cli_evaluate_other_checkpoint PROPERTIES FIXTURES_REQUIRED msm_evaluate_single
    PASS_REGULAR_EXPRESSION "the checkpoint belongs to a different run.*--fresh")

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
    if(NOT args MATCHES "--out")
      string(APPEND args " --out ${MSM_EVALUATE_OUT}/bad")
    endif()
    if(NOT args MATCHES "--scene")
      string(APPEND args " --scene fence")
    endif()
    if(NOT args MATCHES "--candidates")
      string(APPEND args " --candidates power2")
    endif()
    separate_arguments(args UNIX_COMMAND "${args} --size 16 --fresh")
    add_test(NAME msm_cli_evaluate_${name}_fails COMMAND msm evaluate ${args})
    set_tests_properties(msm_cli_evaluate_${name}_fails PROPERTIES WILL_FAIL TRUE)
    add_test(NAME msm_cli_evaluate_${name}_message COMMAND msm evaluate ${args})
    set_tests_properties(msm_cli_evaluate_${name}_message PROPERTIES PASS_REGULAR_EXPRESSION "${message}")
  endforeach()
endif()

# An imported mesh (glmark2-data's bunny, installed by scripts/bootstrap.sh).
if(MSM_BUILD_TESTS AND EXISTS /usr/share/glmark2/models/bunny.obj)
  add_test(NAME msm_cli_evaluate_imported_mesh
    COMMAND msm evaluate --scene ${PROJECT_SOURCE_DIR}/tests/data/evaluate_bunny.json --size 48 --grid 257
      --candidates power4,trig4,hamburger4 --fresh --out ${CMAKE_CURRENT_BINARY_DIR}/evaluate-tests/bunny)
  set_tests_properties(msm_cli_evaluate_imported_mesh PROPERTIES
    PASS_REGULAR_EXPRESSION "3 candidates \\(0 from the checkpoint\\) on 1 scene.*evaluate_bunny.json: [0-9]+ fragments \\([0-9]+ receive light")
endif()
