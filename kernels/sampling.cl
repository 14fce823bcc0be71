/* Warps from [0,1)^n to sampled domains, each with its pdf twin named by measure and taking
 * exactly what the routine returns. Samplers never draw their own random numbers. */
#ifndef MCRT_SAMPLING_CL
#define MCRT_SAMPLING_CL

/* Uniform point on a triangle, returned as barycentrics (b1, b2) of p1, p2: b0 = 1 − √u0,
 * b1 = u1·√u0 (Osada et al. 2002; PBRT 3rd ed. 13.6.5). */
inline float2 sample_triangle_uniform(float2 u) {
    float su0 = sqrt(u.x);
    float b0 = 1.0f - su0;
    float b1 = u.y * su0;
    return (float2)(b1, 1.0f - b0 - b1);
}

/* Density of sample_triangle_uniform with respect to area on a triangle of the given area. */
inline float sample_triangle_uniform_pdf_a(float area) { return 1.0f / area; }

#endif
