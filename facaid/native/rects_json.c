/* Rectangles as JSON in C, for `facaid.native.rects.rects_json`: the segmentation contract's list of rectangles
 * written without building a dict per rectangle. */
#include <stdint.h>
#include <string.h>

/* The rows (label, x0, y0, x1, y1) as the segmentation contract's JSON list of rectangles, byte for byte what
 * orjson writes for `facaid.segmentation.rect_dicts`: [{"label":"window","x0":1,"y0":2,"x1":3,"y1":4},...].
 * names: the 12 label names, each ended by a NUL. Returns the bytes written to out (room for cap), or the bytes
 * needed when that is more than cap (nothing usable is written then), or -2 for a label outside 0..11. */
static char *put_int(char *p, int64_t v) {
    char tmp[24];
    int k = 0;
    uint64_t u = v < 0 ? (uint64_t)(-(v + 1)) + 1 : (uint64_t)v;
    if (v < 0) *p++ = '-';
    do { tmp[k++] = (char)('0' + u % 10); u /= 10; } while (u);
    while (k) *p++ = tmp[--k];
    return p;
}

int64_t facaid_rects_json(const int64_t *rows, int64_t n, const char *names, char *out, int64_t cap) {
    const char *name[12];
    size_t len[12];
    for (int i = 0; i < 12; i++) { name[i] = names; len[i] = strlen(names); names += len[i] + 1; }
    int64_t need = 2;
    for (int64_t i = 0; i < n; i++) {
        if (rows[5 * i] < 0 || rows[5 * i] > 11) return -2;
        need += 34 + (int64_t)len[rows[5 * i]] + 4 * 21; /* the fixed text, the name, four integers at most */
    }
    if (need > cap) return need;
    static const char *keys[4] = {"\",\"x0\":", ",\"y0\":", ",\"x1\":", ",\"y1\":"};
    char *p = out;
    *p++ = '[';
    for (int64_t i = 0; i < n; i++) {
        const int64_t *r = rows + 5 * i;
        if (i) *p++ = ',';
        memcpy(p, "{\"label\":\"", 10); p += 10;
        memcpy(p, name[r[0]], len[r[0]]); p += len[r[0]];
        for (int j = 0; j < 4; j++) {
            size_t kl = strlen(keys[j]);
            memcpy(p, keys[j], kl); p += kl;
            p = put_int(p, r[1 + j]);
        }
        *p++ = '}';
    }
    *p++ = ']';
    return p - out;
}
