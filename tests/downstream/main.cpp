#include <cstdio>
#include <msm/msm.h>
int main() {
  msm::vec4 b = msm::msm_apply_bias(msm::msm_moments4(-0.5f), msm::msm_moment_bias(msm::MSM_REP_SIGNED_FLOAT));
  float shadow = msm::msm_hamburger4_lower(b, 0.5f); // the only occluder is in front: shadowed
  std::printf("shadow %.3f\n", shadow);
  return shadow > 0.99f ? 0 : 1;
}
