// Umbrella header: every shared (GLSL + C++) header of msm.
#ifndef MSM_MSM_H
#define MSM_MSM_H
#include "msm/shared.h"
#include "msm/config.h"
#endif
