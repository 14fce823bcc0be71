/* Watertight ray–triangle intersection (Woop, Benthin, Wald 2013, JCGT 2(1)): no ray passes
 * between two triangles sharing an edge, whatever the rounding. */
#ifndef MCRT_INTERSECT_CL
#define MCRT_INTERSECT_CL

#include "geometry.cl"

/* The edge functions of a shared edge must round identically in both triangles: a fused
 * multiply-add in one and not the other would open cracks (Woop et al. 2013, sec. 4). */
#pragma OPENCL FP_CONTRACT OFF

#if defined(cl_khr_fp64)
#pragma OPENCL EXTENSION cl_khr_fp64 : enable
#define MCRT_HAVE_FP64 1
#endif

/* On a hit with t in (0, t_max): returns true and sets *t and the barycentrics b1, b2 of p1, p2. */
inline bool intersect_triangle(const Ray* r, float4 p0, float4 p1, float4 p2, float t_max,
                               float* t_hit, float* b1, float* b2) {
    /* Translate to the ray origin, permute so that z is the dominant axis, shear (sec. 3). */
    float4 a = shuffle(p0 - (float4)(r->org, 0.0f), r->shear_axes);
    float4 b = shuffle(p1 - (float4)(r->org, 0.0f), r->shear_axes);
    float4 c = shuffle(p2 - (float4)(r->org, 0.0f), r->shear_axes);
    float ax = a.x - r->shear.x * a.z, ay = a.y - r->shear.y * a.z;
    float bx = b.x - r->shear.x * b.z, by = b.y - r->shear.y * b.z;
    float cx = c.x - r->shear.x * c.z, cy = c.y - r->shear.y * c.z;

    /* Scaled barycentrics as 2D edge functions. */
    float u = cx * by - cy * bx;
    float v = ax * cy - ay * cx;
    float w = bx * ay - by * ax;
#ifdef MCRT_HAVE_FP64
    /* An exact zero may be a rounding artefact on a shared edge: recompute in double. */
    if (u == 0.0f || v == 0.0f || w == 0.0f) {
        u = (float)((double)cx * (double)by - (double)cy * (double)bx);
        v = (float)((double)ax * (double)cy - (double)ay * (double)cx);
        w = (float)((double)bx * (double)ay - (double)by * (double)ax);
    }
#endif
    if ((u < 0.0f || v < 0.0f || w < 0.0f) && (u > 0.0f || v > 0.0f || w > 0.0f)) return false;
    float det = u + v + w;
    if (det == 0.0f) return false;

    /* Scaled hit distance; compare before dividing. */
    float az = r->shear.z * a.z, bz = r->shear.z * b.z, cz = r->shear.z * c.z;
    float t_scaled = u * az + v * bz + w * cz;
    float inv_det = 1.0f / det;
    float t = t_scaled * inv_det;
    if (!(t > 0.0f && t < t_max)) return false;
    *t_hit = t;
    *b1 = v * inv_det;
    *b2 = w * inv_det;
    return true;
}

/* Contraction is harmless, and faster, in the rest of the program. */
#pragma OPENCL FP_CONTRACT ON
#endif
