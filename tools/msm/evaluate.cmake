# msm evaluate (issue 16): the command and its CLI tests, kept apart from the other commands' file.
target_sources(msm PRIVATE ${CMAKE_CURRENT_LIST_DIR}/evaluate.cpp)
target_link_libraries(msm PRIVATE msm::evaluate_mpi)
