/* Texture lookups (-D MCRT_TEXTURES builds): the texel data of RENDER_ARG_TEXTURES, read with
 * each slot's sampler (glTF 2.0 "Samplers", "Texture Data") and KHR_texture_transform; the
 * host's twin is host/scene/texture_lookup.cpp, which computes emitters' powers with the same
 * arithmetic. One mip level: Monte Carlo integration over the pixel filters a minified texture
 * (docs/MATERIALS.md "Textures"), so magFilter decides NEAREST or bilinear everywhere. */
#ifndef MCRT_TEXTURES_CL
#define MCRT_TEXTURES_CL

#include "shared_types.h"

typedef struct {
    global const uint* data;                /* TextureHeader, MaterialTextures, images, ... */
    global const TriangleSurface* surfaces; /* per packet lane */
} TextureView;

inline global const MaterialTextures* material_textures(const TextureView* tv, uint material) {
    return (global const MaterialTextures*)(tv->data + 4) + material;
}

inline bool texture_slot_used(global const TextureSlot* slot) {
    return slot->image != MCRT_NO_TEXTURE;
}

/* The corners' texture coordinates interpolated at barycentrics (b1, b2) of vertices 1 and 2:
 * .xy TEXCOORD_0, .zw TEXCOORD_1. */
inline float4 surface_uv(const TextureView* tv, uint lane, float b1, float b2) {
    global const TriangleSurface* s = tv->surfaces + lane;
    float b0 = 1.0f - b1 - b2;
    return b0 * s->uv[0] + b1 * s->uv[1] + b2 * s->uv[2];
}

/* Index i of an axis of n texels under a wrap mode (glTF 2.0 "Samplers": REPEAT,
 * CLAMP_TO_EDGE, MIRRORED_REPEAT), in [0, n). */
inline int wrap_texel(int i, int n, uint wrap) {
    if (wrap == TEXTURE_WRAP_CLAMP) return clamp(i, 0, n - 1);
    if (wrap == TEXTURE_WRAP_MIRROR) {
        int m = ((i % (2 * n)) + 2 * n) % (2 * n);
        return m < n ? m : 2 * n - 1 - m;
    }
    return ((i % n) + n) % n;
}

/* Texel (i, j) of an image decoded to linear values: colour through the slot's transfer
 * function (the host's exact tables), alpha always linear. */
inline float4 texel_value(const TextureView* tv, global const TextureImageGpu* image, int i, int j,
                          uint mode) {
    global const TextureHeader* head = (global const TextureHeader*)tv->data;
    uint t = tv->data[head->texels + image->offset + (uint)j * image->width + (uint)i];
    global const float* decode = (global const float*)(tv->data + head->decode);
    global const float* colour = (mode & TEXTURE_SRGB) ? decode : decode + 256;
    return (float4)(colour[t & 0xffu], colour[(t >> 8) & 0xffu], colour[(t >> 16) & 0xffu],
                    decode[256u + (t >> 24)]);
}

/* A texel coordinate bounded before floor: NaN reads texel 0, and no int conversion overflows. */
inline float bounded_texel_coordinate(float x) {
    return isnan(x) ? 0.0f : clamp(x, -0x1.0p24f, 0x1.0p24f);
}

/* The slot's texture at the surface's coordinates uv (surface_uv): transformed, wrapped and
 * filtered (NEAREST or bilinear between texel centres), in linear values. */
inline float4 texture_lookup(const TextureView* tv, global const TextureSlot* slot, float4 uv) {
    global const TextureHeader* head = (global const TextureHeader*)tv->data;
    global const TextureImageGpu* image =
        (global const TextureImageGpu*)(tv->data + head->images) + slot->image;
    float2 st = (slot->mode & TEXTURE_TEXCOORD_1) ? uv.zw : uv.xy;
    float4 m = slot->m;
    float u = (m.x * st.x + m.y * st.y) + slot->offset_u;
    float v = (m.z * st.x + m.w * st.y) + slot->offset_v;
    int w = (int)image->width, h = (int)image->height;
    uint wrap_s = (slot->mode >> TEXTURE_WRAP_S_SHIFT) & 3u;
    uint wrap_t = (slot->mode >> TEXTURE_WRAP_T_SHIFT) & 3u;
    if (!(slot->mode & TEXTURE_LINEAR)) {
        int i = (int)floor(bounded_texel_coordinate(u * (float)w));
        int j = (int)floor(bounded_texel_coordinate(v * (float)h));
        return texel_value(tv, image, wrap_texel(i, w, wrap_s), wrap_texel(j, h, wrap_t),
                           slot->mode);
    }
    float x = bounded_texel_coordinate(u * (float)w - 0.5f);
    float y = bounded_texel_coordinate(v * (float)h - 0.5f);
    float x0 = floor(x), y0 = floor(y);
    float fx = x - x0, fy = y - y0;
    int i0 = wrap_texel((int)x0, w, wrap_s), i1 = wrap_texel((int)x0 + 1, w, wrap_s);
    int j0 = wrap_texel((int)y0, h, wrap_t), j1 = wrap_texel((int)y0 + 1, h, wrap_t);
    float4 c00 = texel_value(tv, image, i0, j0, slot->mode);
    float4 c10 = texel_value(tv, image, i1, j0, slot->mode);
    float4 c01 = texel_value(tv, image, i0, j1, slot->mode);
    float4 c11 = texel_value(tv, image, i1, j1, slot->mode);
    return ((1.0f - fx) * c00 + fx * c10) * (1.0f - fy) + ((1.0f - fx) * c01 + fx * c11) * fy;
}

/* The material's alpha at uv: baseColorFactor.a × the base colour texture's alpha. */
inline float material_alpha(const TextureView* tv, global const MaterialTextures* mt, float4 uv) {
    float a = mt->base_alpha;
    if (texture_slot_used(&mt->base_color)) a *= texture_lookup(tv, &mt->base_color, uv).w;
    return a;
}

/* Chris Wellons' lowbias32 integer hash (2018, "Prospecting for Hash Functions"): mixes every
 * input bit into every output bit, with no state. */
inline uint alpha_hash(uint x) {
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
}

/* True where a ray query keeps the candidate hit at uv on a surface of this material: MASK keeps
 * alpha ≥ alphaCutoff (glTF 2.0 "Alpha Coverage"); BLEND keeps it with probability alpha, by a
 * number in [0, 1) hashed from the query's key and the triangle (stochastic transparency:
 * Enderton et al. 2010), independent between surfaces; OPAQUE keeps it. */
inline bool alpha_keeps(const TextureView* tv, global const MaterialTextures* mt, float4 uv,
                        uint key, uint lane) {
    if (mt->alpha_mode == MATERIAL_ALPHA_OPAQUE) return true;
    float a = material_alpha(tv, mt, uv);
    if (mt->alpha_mode == MATERIAL_ALPHA_MASK) return a >= mt->alpha_cutoff;
    float xi = (float)(alpha_hash(key ^ alpha_hash(lane + 0x9e3779b9u)) >> 8) * 0x1.0p-24f;
    return xi < a;
}

#endif
