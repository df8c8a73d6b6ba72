/// \file bvh8_kernel_avx512.cpp
/// The BVH8 single-ray kernel for AVX-512 (the same source as the AVX2 one, eight
/// lanes in AVX-512VL instructions with mask registers; -mavx512f -mavx512vl).
#define BSPRT_BVH8_ENTRY bvh8_trace_avx512
#define BSPRT_BVH8_OCCLUDED bvh8_occluded_avx512
#define BSPRT_BVH8_BATCH bvh8_trace_batch_avx512
#include "traverse/bvh/bvh8_kernel.inl"
