/// \file bvh8_kernel_base.cpp
/// The BVH8 single-ray kernel for plain x86-64 (the same source as the AVX2 one,
/// eight lanes emulated by the compiler), for CPUs without AVX2.
// The kernel's 32-byte vectors never cross a non-inline call here; GCC warns
// about their ABI all the same.
#pragma GCC diagnostic ignored "-Wpsabi"
#define BSPRT_BVH8_ENTRY bvh8_trace_base
#define BSPRT_BVH8_OCCLUDED bvh8_occluded_base
#define BSPRT_BVH8_BATCH bvh8_trace_batch_base
#include "traverse/bvh/bvh8_kernel.inl"
