// The descriptor bindings of msm::vk's own shaders, named once for the shaders and their hosts
// (context.cpp's fma probe, vk_test.cpp's self-tests). Valid as GLSL and C++.
#ifndef MSM_VK_BINDINGS_H
#define MSM_VK_BINDINGS_H

#define MSM_BINDING_FMA_PROBE_CASES 0 // fma_probe.comp: the cases in, the results after them

#define MSM_BINDING_SELFTEST_SOURCE 0 // selftest.comp, selftest_fma.comp: storage buffers
#define MSM_BINDING_SELFTEST_DESTINATION 1

#define MSM_BINDING_SELFTEST_IMAGE_SOURCE 0 // selftest_image.comp: storage images
#define MSM_BINDING_SELFTEST_IMAGE_RESULT 1
#define MSM_BINDING_SELFTEST_IMAGE_TABLE 2  // a sampled image
#define MSM_BINDING_SELFTEST_IMAGE_PARAMS 3 // a uniform buffer

#endif // MSM_VK_BINDINGS_H
