// The version of msm, valid GLSL and C++ like the other shared headers. CMake reads its project
// version from here (CMakeLists.txt), so this is the one place to change it.
// MSM_VERSION is major * 10000 + minor * 100 + patch.
#ifndef MSM_VERSION_H
#define MSM_VERSION_H
#define MSM_VERSION_MAJOR 0
#define MSM_VERSION_MINOR 2
#define MSM_VERSION_PATCH 0
#define MSM_VERSION (MSM_VERSION_MAJOR * 10000 + MSM_VERSION_MINOR * 100 + MSM_VERSION_PATCH)
#endif // MSM_VERSION_H
