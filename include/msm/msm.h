// Umbrella header: every shared (GLSL + C++) header of msm.
#ifndef MSM_MSM_H
#define MSM_MSM_H
#include "msm/baselines.h"
#include "msm/bias.h"
#include "msm/blocker.h"
#include "msm/config.h"
#include "msm/eft.h"
#include "msm/filter.h"
#include "msm/hamburger4.h"
#include "msm/hamburger6.h"
#include "msm/hausdorff4.h"
#include "msm/moments.h"
#include "msm/nonlinear.h"
#include "msm/quantize.h"
#include "msm/roots.h"
#include "msm/sat.h"
#include "msm/shading.h"
#include "msm/shared.h"
#include "msm/soft.h"
#include "msm/three_moments.h"
#include "msm/trigonometric.h"
#include "msm/version.h"
#endif
