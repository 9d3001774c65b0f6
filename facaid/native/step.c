/* One decoder step of FacaidModel's GPT-2 decoder for K rows that read one encoder memory, in plain C.

   The same arithmetic as the torch decoder's cached step (facaid/model/decoder.py; pre-layer-norm self-attention on a
   key/value cache, cross-attention on the memory with an additive mask, tanh-GELU MLP, final layer norm and
   the output head), written so that the compiler vectorizes every inner loop without reassociating sums:
   matrix-vector products as sums of scaled rows (weights stored (in, out)), keys stored transposed (dh, T) so
   that a head's scores are sums of scaled key rows, and e^x without library calls (fast_expf). At a few hundred
   steps of one token, torch's fixed cost per operation (a few microseconds, about 16 operations a block)
   outweighs this arithmetic; one call does it all.

   Built and loaded by facaid/native/__init__.py; checked against the torch decoder to 1e-5 by
   tests/model/test_native.py. */

#include <math.h>
#include <stddef.h>
#include <string.h>

enum {
    LN1_G, LN1_B, ATTN_W, ATTN_B, PROJ_W, PROJ_B,
    LNC_G, LNC_B, Q_W, Q_B, CPROJ_W, CPROJ_B,
    LN2_G, LN2_B, FC_W, FC_B, MPROJ_W, MPROJ_B,
    CROSS_K, CROSS_V, SELF_K, SELF_V,
    BLOCK_PTRS
};

/* y[r] (+)= x[r] @ W + b for the K rows; W (n_in, n_out) row-major, each of its rows read once for all K
   rows. With acc, y already holds a residual. */
static void matvec(int k, const float *restrict x, int x_stride, const float *restrict w, const float *restrict b,
                   float *restrict y, int y_stride, int n_in, int n_out, int acc) {
    for (int r = 0; r < k; r++) {
        float *restrict yr = y + (size_t)r * y_stride;
        if (!acc) {
            if (b) memcpy(yr, b, sizeof(float) * n_out); else memset(yr, 0, sizeof(float) * n_out);
        } else if (b) {
            for (int j = 0; j < n_out; j++) yr[j] += b[j];
        }
    }
    int i = 0;
    for (; i + 4 <= n_in; i += 4) {  /* four weight rows at a time: a quarter of the loads and stores of y */
        const float *restrict w0 = w + (size_t)i * n_out, *restrict w1 = w0 + n_out;
        const float *restrict w2 = w1 + n_out, *restrict w3 = w2 + n_out;
        int r = 0;
        for (; r + 4 <= k; r += 4) {  /* and four rows of x: each weight loaded serves four rows */
            const float *xa = x + (size_t)r * x_stride + i, *xb = xa + x_stride;
            const float *xc = xb + x_stride, *xd = xc + x_stride;
            const float a0 = xa[0], a1 = xa[1], a2 = xa[2], a3 = xa[3], b0 = xb[0], b1 = xb[1], b2 = xb[2], b3 = xb[3];
            const float c0 = xc[0], c1 = xc[1], c2 = xc[2], c3 = xc[3], d0 = xd[0], d1 = xd[1], d2 = xd[2], d3 = xd[3];
            float *restrict ya = y + (size_t)r * y_stride, *restrict yb = ya + y_stride;
            float *restrict yc = yb + y_stride, *restrict yd = yc + y_stride;
            for (int j = 0; j < n_out; j++) {
                const float p0 = w0[j], p1 = w1[j], p2 = w2[j], p3 = w3[j];
                ya[j] += a0 * p0 + a1 * p1 + a2 * p2 + a3 * p3;
                yb[j] += b0 * p0 + b1 * p1 + b2 * p2 + b3 * p3;
                yc[j] += c0 * p0 + c1 * p1 + c2 * p2 + c3 * p3;
                yd[j] += d0 * p0 + d1 * p1 + d2 * p2 + d3 * p3;
            }
        }
        for (; r < k; r++) {
            const float *xr = x + (size_t)r * x_stride + i;
            const float x0 = xr[0], x1 = xr[1], x2 = xr[2], x3 = xr[3];
            float *restrict yr = y + (size_t)r * y_stride;
            for (int j = 0; j < n_out; j++) yr[j] += x0 * w0[j] + x1 * w1[j] + x2 * w2[j] + x3 * w3[j];
        }
    }
    for (; i < n_in; i++) {
        const float *restrict wi = w + (size_t)i * n_out;
        for (int r = 0; r < k; r++) {
            const float xi = x[(size_t)r * x_stride + i];
            float *restrict yr = y + (size_t)r * y_stride;
            for (int j = 0; j < n_out; j++) yr[j] += xi * wi[j];
        }
    }
}

static void layer_norm(int k, int d, const float *restrict x, const float *restrict g, const float *restrict b,
                       float eps, float *restrict y) {
    for (int r = 0; r < k; r++) {
        const float *xr = x + (size_t)r * d;
        float *yr = y + (size_t)r * d;
        float mean = 0.f, var = 0.f;
        for (int i = 0; i < d; i++) mean += xr[i];
        mean /= d;
        for (int i = 0; i < d; i++) { float c = xr[i] - mean; var += c * c; }
        const float inv = 1.f / sqrtf(var / d + eps);
        for (int i = 0; i < d; i++) yr[i] = (xr[i] - mean) * inv * g[i] + b[i];
    }
}

/* e^x to about 2 ulp (Cephes' expf: 2^n times a polynomial on [-ln 2 / 2, ln 2 / 2]) without branches or calls,
   so that loops over it vectorize; below -87.3 it gives the smallest normal float rather than 0. */
static inline float fast_expf(float x) {
    x = x < -87.3f ? -87.3f : x > 88.7f ? 88.7f : x;  /* (not fminf / fmaxf, which do not vectorize) */
    /* n = round(x / ln 2): adding 1.5 * 2^23 leaves n in the low bits of t (nor floorf: it does not vectorize) */
    const float t = x * 1.44269504088896341f + 12582912.f;
    const float n = t - 12582912.f;
    union { float f; int i; } bits = {.f = t};
    union { int i; float f; } scale = {.i = (bits.i - 0x4B400000 + 127) << 23};  /* 2^n */
    x = x - n * 0.693359375f + n * 2.12194440e-4f;
    float p = 1.9875691500e-4f;
    p = p * x + 1.3981999507e-3f;
    p = p * x + 8.3334519073e-3f;
    p = p * x + 4.1665795894e-2f;
    p = p * x + 1.6666665459e-1f;
    p = p * x + 5.0000001201e-1f;
    p = p * x * x + x + 1.f;
    return p * scale.f;
}

/* softmax of s[0..n) in place */
static void softmax(float *restrict s, int n) {
    float m = s[0];
    for (int i = 1; i < n; i++) m = s[i] > m ? s[i] : m;
    for (int i = 0; i < n; i++) s[i] = fast_expf(s[i] - m);
    float sum = 0.f;
    for (int i = 0; i < n; i++) sum += s[i];
    const float inv = 1.f / sum;
    for (int i = 0; i < n; i++) s[i] *= inv;
}

/* out (dh) = softmax(scale * q . keys + mask) @ values for one head: keys (dh, n) with row stride kstride,
   values (n, dh). */
static void attend(const float *restrict q, const float *restrict keys, size_t kstride, const float *restrict values,
                   const float *restrict mask, int n, int dh, float scale, float *restrict s, float *restrict out) {
    memset(s, 0, sizeof(float) * n);
    int i = 0;
    for (; i + 4 <= dh; i += 4) {
        const float q0 = q[i] * scale, q1 = q[i + 1] * scale, q2 = q[i + 2] * scale, q3 = q[i + 3] * scale;
        const float *restrict k0 = keys + (size_t)i * kstride, *restrict k1 = k0 + kstride;
        const float *restrict k2 = k1 + kstride, *restrict k3 = k2 + kstride;
        for (int j = 0; j < n; j++) s[j] += q0 * k0[j] + q1 * k1[j] + q2 * k2[j] + q3 * k3[j];
    }
    for (; i < dh; i++) {
        const float qi = q[i] * scale;
        const float *restrict ki = keys + (size_t)i * kstride;
        for (int j = 0; j < n; j++) s[j] += qi * ki[j];
    }
    if (mask) for (int j = 0; j < n; j++) s[j] += mask[j];
    softmax(s, n);
    if (dh == 32) {  /* the shipped model's head size: the sum stays in registers instead of going through out */
        float acc[32] = {0};
        for (int j = 0; j < n; j++) {
            const float p = s[j];
            const float *restrict vj = values + (size_t)j * 32;
            for (int c = 0; c < 32; c++) acc[c] += p * vj[c];
        }
        memcpy(out, acc, sizeof acc);
        return;
    }
    memset(out, 0, sizeof(float) * dh);
    for (int j = 0; j < n; j++) {
        const float p = s[j];
        const float *restrict vj = values + (size_t)j * dh;
        for (int i = 0; i < dh; i++) out[i] += p * vj[i];
    }
}

/* One step for K rows at position t. blocks: BLOCK_PTRS pointers per block (see the enum); the self cache of a
   block holds keys (K, H, dh, L) and values (K, H, L, dh); cross keys (H, dh, M), values (H, M, dh). mask: the
   additive cross-attention mask, element (h, r, m) at h * mask_h + r * mask_r + m, or NULL. x (K, d): the
   embedded tokens; wpe_t (d): the position embedding of t. work: at least K * (6 d + f) + max(L, M) floats
   (x, h, qkv, att, hid, then the scores). out (K, V): logits. */
int facaid_step(int n_blocks, void **blocks, int k, int d, int heads, int f, int m, int l, int t, int v,
                const float *x_in, const float *wpe_t, const float *mask, long mask_h, long mask_r,
                const float *lnf_g, const float *lnf_b, const float *head_wt, const float *head_b, float eps,
                float *work, float *out) {
    if (t < 0 || t >= l) return 1;
    const int dh = d / heads;
    const float scale = 1.f / sqrtf((float)dh);
    float *x = work, *h = x + (size_t)k * d, *qkv = h + (size_t)k * d, *att = qkv + (size_t)k * 3 * d;
    float *hid = att + (size_t)k * d, *s = hid + (size_t)k * f;
    for (int r = 0; r < k; r++)
        for (int i = 0; i < d; i++) x[(size_t)r * d + i] = x_in[(size_t)r * d + i] + wpe_t[i];
    for (int bi = 0; bi < n_blocks; bi++) {
        const float **p = (const float **)(blocks + (size_t)bi * BLOCK_PTRS);
        float *self_k = (float *)p[SELF_K], *self_v = (float *)p[SELF_V];
        /* self-attention */
        layer_norm(k, d, x, p[LN1_G], p[LN1_B], eps, h);
        matvec(k, h, d, p[ATTN_W], p[ATTN_B], qkv, 3 * d, d, 3 * d, 0);
        for (int r = 0; r < k; r++) {
            const float *q = qkv + (size_t)r * 3 * d, *kn = q + d, *vn = q + 2 * d;
            for (int hh = 0; hh < heads; hh++) {
                float *kc = self_k + ((size_t)r * heads + hh) * dh * l;  /* (dh, L) */
                float *vc = self_v + ((size_t)r * heads + hh) * l * dh;  /* (L, dh) */
                for (int i = 0; i < dh; i++) kc[(size_t)i * l + t] = kn[hh * dh + i];
                memcpy(vc + (size_t)t * dh, vn + hh * dh, sizeof(float) * dh);
                attend(q + hh * dh, kc, l, vc, NULL, t + 1, dh, scale, s, att + (size_t)r * d + hh * dh);
            }
        }
        matvec(k, att, d, p[PROJ_W], p[PROJ_B], x, d, d, d, 1);
        /* cross-attention */
        layer_norm(k, d, x, p[LNC_G], p[LNC_B], eps, h);
        matvec(k, h, d, p[Q_W], p[Q_B], qkv, d, d, d, 0);
        for (int r = 0; r < k; r++)
            for (int hh = 0; hh < heads; hh++)
                attend(qkv + (size_t)r * d + hh * dh, p[CROSS_K] + (size_t)hh * dh * m, m,
                       p[CROSS_V] + (size_t)hh * m * dh, mask ? mask + hh * mask_h + r * mask_r : NULL, m, dh,
                       scale, s, att + (size_t)r * d + hh * dh);
        matvec(k, att, d, p[CPROJ_W], p[CPROJ_B], x, d, d, d, 1);
        /* MLP */
        layer_norm(k, d, x, p[LN2_G], p[LN2_B], eps, h);
        matvec(k, h, d, p[FC_W], p[FC_B], hid, f, d, f, 0);
        for (size_t i = 0; i < (size_t)k * f; i++) {
            const float u = hid[i];
            /* 1 + tanh(z) = 2 - 2 / (e^2z + 1) */
            const float z = 0.7978845608028654f * (u + 0.044715f * u * u * u);
            hid[i] = u * (1.f - 1.f / (fast_expf(2.f * z) + 1.f));
        }
        matvec(k, hid, f, p[MPROJ_W], p[MPROJ_B], x, d, f, d, 1);
    }
    layer_norm(k, d, x, lnf_g, lnf_b, eps, h);
    matvec(k, h, d, head_wt, head_b, out, v, d, v, 0);
    return 0;
}
