/* Test entry points for kernels/lights/environment.cl (tests/scene/test_environment.cpp). Global sizes are
 * 1D; each entry checks its bound. */
#include "environment.cl"

/* Reads u[k] = (u_select, u_fine, u.x, u.y); writes out[k] = (wi, pdf_w) of the sample and
 * check[k] = (environment_map_pdf_w at wi, its texel index as a float, the sample's texel, the
 * radiance's red at wi). */
kernel void environment_samples(global const float* rgb, global const float* cdf, uint width,
                                uint height, float cos_rot, float sin_rot, uint count,
                                global const float4* u, global float4* out, global float4* check) {
    uint k = (uint)get_global_id(0);
    if (k >= count) return;
    EnvironmentMapView env = {rgb, cdf, width, height, cos_rot, sin_rot};
    EnvironmentSample s = sample_environment_map(&env, u[k].x, u[k].y, u[k].zw);
    out[k] = (float4)(s.wi, s.pdf_w);
    check[k] = (float4)(environment_map_pdf_w(&env, s.wi), (float)environment_texel(&env, s.wi),
                        (float)s.texel, environment_map_radiance(&env, s.wi).x);
}
