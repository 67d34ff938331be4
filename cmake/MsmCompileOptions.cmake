# Warning and sanitizer flags shared by every msm target.
add_library(msm_compile_options INTERFACE)
target_compile_options(msm_compile_options INTERFACE -Wall -Wextra -Wno-unused-parameter
  # The CPU build of the shared math must round like the GPU: no fused multiply-adds by surprise.
  -ffp-contract=off)
if(MSM_WERROR)
  target_compile_options(msm_compile_options INTERFACE -Werror)
  # GCC 12 at -O3 reports libstdc++'s own std::string code: -Wrestrict on "literal" + string
  # (GCC PR 105329) and -Wmaybe-uninitialized on strings in designated initializers (PR 105562).
  # They stay warnings there; everything else is an error.
  if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU" AND CMAKE_CXX_COMPILER_VERSION VERSION_LESS 13)
    target_compile_options(msm_compile_options INTERFACE -Wno-error=restrict -Wno-error=maybe-uninitialized)
  endif()
endif()
if(MSM_SANITIZE)
  target_compile_options(msm_compile_options INTERFACE -fsanitize=${MSM_SANITIZE} -fno-omit-frame-pointer)
  target_link_options(msm_compile_options INTERFACE -fsanitize=${MSM_SANITIZE})
endif()
if(MSM_BUILD_FUZZERS)
  if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    message(FATAL_ERROR "MSM_BUILD_FUZZERS needs clang (libFuzzer): CXX=clang++-16")
  endif()
  # Coverage feedback from all of msm's code; the fuzz targets link libFuzzer itself.
  target_compile_options(msm_compile_options INTERFACE -fsanitize=fuzzer-no-link)
endif()
msm_install_library(msm_compile_options COMPONENT math) # the installed static libraries link it

# Test support (tests/support: the Vulkan test fixture, the glTF writer) and the one place of test
# data: tests/data, and the real models no one here wrote, from Debian packages that
# scripts/bootstrap.sh installs, by configured paths (a test whose model is missing fails, it does
# not skip). For test targets only, never installed.
set(MSM_ASSIMP_MODELS_DIR /usr/share/assimp/models CACHE PATH "assimp-testmodels' models (glTF samples)")
set(MSM_GLMARK2_MODELS_DIR /usr/share/glmark2/models CACHE PATH "glmark2-data's models (the bunny)")
set(MSM_STUDIOLIGHTS_DIR /usr/share/blender/datafiles/studiolights/world
  CACHE PATH "blender-data's CC0 equirectangular HDR light probes")
add_library(msm_test_support INTERFACE)
target_include_directories(msm_test_support INTERFACE ${PROJECT_SOURCE_DIR}/tests/support)
target_compile_definitions(msm_test_support INTERFACE MSM_TEST_DATA_DIR="${PROJECT_SOURCE_DIR}/tests/data"
  MSM_ASSIMP_MODELS_DIR="${MSM_ASSIMP_MODELS_DIR}" MSM_GLMARK2_MODELS_DIR="${MSM_GLMARK2_MODELS_DIR}"
  MSM_STUDIOLIGHTS_DIR="${MSM_STUDIOLIGHTS_DIR}")

# msm_add_test(NAME SOURCES... LIBS ...): one GoogleTest executable, its tests registered with CTest.
function(msm_add_test name)
  cmake_parse_arguments(ARG "" "" "SOURCES;LIBS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_LIBS} GTest::gtest_main msm_compile_options msm_test_support)
  gtest_discover_tests(${name} DISCOVERY_TIMEOUT 60 PROPERTIES TIMEOUT 900)
endfunction()
