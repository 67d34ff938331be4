// outputs[i] = msm_test_kernel(function, inputs[i]): the shared math of include/msm/ on the device,
// for gpu_math_test.cpp, which runs the same kernels.h on the CPU and compares.
#version 460
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 64) in;

layout(push_constant) uniform Push {
  int function_id; // MSM_K_*
  uint count;      // entries in inputs and outputs
} pc;

// msm_fma (shared.h) is exact on every device: create_program specializes msm_fused_fma to the
// Context's probe of fma(), so this runs the emulation where fma() is not fused (lavapipe).
#include "kernels.h"

layout(std430, binding = MSM_BINDING_KERNELS_INPUTS) readonly buffer Inputs { KernelIO inputs[]; };
layout(std430, binding = MSM_BINDING_KERNELS_OUTPUTS) writeonly buffer Outputs { KernelIO outputs[]; };

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i < pc.count) outputs[i] = msm_test_kernel(pc.function_id, inputs[i]);
}
