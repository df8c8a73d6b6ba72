/// \file bvh8_kernel_avx2.cpp
/// The BVH8 single-ray kernel for AVX2 (compiled with -mavx2 -mfma -ffp-contract=off).
#define BSPRT_BVH8_ENTRY bvh8_trace_avx2
#define BSPRT_BVH8_OCCLUDED bvh8_occluded_avx2
#define BSPRT_BVH8_BATCH bvh8_trace_batch_avx2
#include "traverse/bvh/bvh8_kernel.inl"
