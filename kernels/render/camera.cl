/* Camera rays (DESIGN.md "Camera contract"). */
#ifndef MCRT_CAMERA_CL
#define MCRT_CAMERA_CL

/* Ray through the point (i + jitter.x, j + jitter.y) of pixel column i, row j (row 0 on top). */
inline float3 camera_direction(global const CameraGpu* cam, uint i, uint j, float2 jitter,
                               uint width, uint height) {
    float x = 2.0f * ((float)i + jitter.x) / (float)width - 1.0f;
    float y = 1.0f - 2.0f * ((float)j + jitter.y) / (float)height;
    return normalize(cam->forward.xyz + x * cam->right.xyz + y * cam->up.xyz);
}

#endif
