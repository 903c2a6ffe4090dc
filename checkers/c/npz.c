/* npz.c: the reader (~100 lines) and writer of npz.h. See golden/FORMAT.md, section "The npz files". */
#include "npz.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static uint32_t u16(const unsigned char *p) { return (uint32_t)p[0] | (uint32_t)p[1] << 8; }
static uint32_t u32(const unsigned char *p) { return u16(p) | u16(p + 2) << 16; }
static uint64_t u64(const unsigned char *p) { return (uint64_t)u32(p) | (uint64_t)u32(p + 4) << 32; }

/* ------------------------------------------------------------------------------------------------ reader */

static int fail(char *err, size_t len, const char *what, const char *name) {
    snprintf(err, len, "%s: %s", name, what);
    return -1;
}

/* Parse the NPY file at p (n bytes) into out. */
static int parse_npy(const unsigned char *p, uint64_t n, npy_array *out, char *err, size_t len, const char *name) {
    if (n < 10 || memcmp(p, "\x93NUMPY", 6) != 0) return fail(err, len, "not an NPY entry", name);
    int major = p[6];
    uint64_t hlen = major == 1 ? u16(p + 8) : u32(p + 8), start = major == 1 ? 10 : 12;
    if (major < 1 || major > 3 || start + hlen > n) return fail(err, len, "unknown NPY version", name);
    char header[4096];
    if (hlen >= sizeof header) return fail(err, len, "NPY header too long", name);
    memcpy(header, p + start, hlen);
    header[hlen] = 0;
    const char *d = strstr(header, "'descr':"), *f = strstr(header, "'fortran_order':");
    const char *s = strstr(header, "'shape':");
    if (!d || !f || !s) return fail(err, len, "NPY header without descr, fortran_order or shape", name);
    d = strchr(d + 8, '\'');
    if (d && strncmp(d, "'<f8'", 5) == 0) out->kind = 'f';
    else if (d && strncmp(d, "'<i8'", 5) == 0) out->kind = 'i';
    else return fail(err, len, "dtype is not '<f8' or '<i8' (FORMAT.md: float64 or int64, little-endian)", name);
    if (strncmp(f + 16 + strspn(f + 16, " "), "False", 5) != 0) return fail(err, len, "Fortran order", name);
    s = strchr(s, '(');
    if (!s) return fail(err, len, "bad shape", name);
    out->ndim = 0;
    out->size = 1;
    for (s++; *s && *s != ')';) {
        char *end;
        long v = strtol(s, &end, 10);
        if (end == s) { s++; continue; }      /* ", " between the numbers */
        if (out->ndim == NPY_MAX_DIM) return fail(err, len, "too many dimensions", name);
        out->shape[out->ndim++] = v;
        out->size *= v;
        s = end;
    }
    if (start + hlen + 8 * (uint64_t)out->size > n) return fail(err, len, "NPY data shorter than its shape", name);
    void *data = malloc(8 * (size_t)out->size + 8);
    if (!data) return fail(err, len, "out of memory", name);
    memcpy(data, p + start + hlen, 8 * (size_t)out->size);   /* a little-endian host: the bytes are the numbers */
    out->f = out->kind == 'f' ? data : NULL;
    out->i = out->kind == 'i' ? data : NULL;
    return 0;
}

int npz_read(const char *path, const char *name, npy_array *out, char *err, size_t len) {
    memset(out, 0, sizeof *out);
    FILE *fp = fopen(path, "rb");
    if (!fp) return fail(err, len, "cannot open", path);
    fseek(fp, 0, SEEK_END);
    long n = ftell(fp);
    fseek(fp, 0, SEEK_SET);
    unsigned char *buf = malloc(n > 0 ? (size_t)n : 1);
    if (!buf || fread(buf, 1, (size_t)n, fp) != (size_t)n) {
        fclose(fp);
        free(buf);
        return fail(err, len, "cannot read", path);
    }
    fclose(fp);
    char want[256];
    snprintf(want, sizeof want, "%s.npy", name);
    int rc = fail(err, len, "no such array", name);
    for (long pos = 0; pos + 30 <= n && u32(buf + pos) == 0x04034b50;) {      /* the local file headers */
        const unsigned char *h = buf + pos;
        uint32_t flags = u16(h + 6), method = u16(h + 8), nlen = u16(h + 26), xlen = u16(h + 28);
        uint64_t usize = u32(h + 22), csize = u32(h + 18);
        const unsigned char *x = h + 30 + nlen, *data = x + xlen;
        for (const unsigned char *e = x; e + 4 <= x + xlen; e += 4 + u16(e + 2)) {  /* zip64: the sizes are here */
            if (u16(e) != 1) continue;
            const unsigned char *q = e + 4;
            if (usize == 0xFFFFFFFFu) { usize = u64(q); q += 8; }
            if (csize == 0xFFFFFFFFu) csize = u64(q);
        }
        if (method != 0) {
            rc = fail(err, len, "compressed entry (golden files are np.savez, uncompressed)", path);
            break;
        }
        if (flags & 8) { rc = fail(err, len, "zip data descriptor (sizes after the data) not supported", path); break; }
        if (data + csize > buf + n) { rc = fail(err, len, "truncated zip entry", path); break; }
        if (nlen == strlen(want) && memcmp(h + 30, want, nlen) == 0) {
            rc = parse_npy(data, csize, out, err, len, name);
            break;
        }
        pos = (long)(data - buf) + (long)csize;
    }
    free(buf);
    return rc;
}

void npy_free(npy_array *a) {
    free(a->f ? (void *)a->f : (void *)a->i);
    a->f = NULL;
    a->i = NULL;
}

/* ------------------------------------------------------------------------------------------------ writer */

static uint32_t crc32(const unsigned char *p, size_t n) {
    uint32_t c = 0xFFFFFFFFu;
    for (size_t k = 0; k < n; k++) {
        c ^= p[k];
        for (int b = 0; b < 8; b++) c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u)));
    }
    return ~c;
}

static void put16(unsigned char *p, uint32_t v) { p[0] = v & 255; p[1] = (v >> 8) & 255; }
static void put32(unsigned char *p, uint32_t v) { put16(p, v & 0xFFFF); put16(p + 2, v >> 16); }

int npz_begin(npz_writer *w, const char *path) {
    memset(w, 0, sizeof *w);
    w->file = fopen(path, "wb");
    return w->file ? 0 : -1;
}

int npz_add(npz_writer *w, const char *name, const double *data, int ndim, const long *shape) {
    if (w->n == 64 || strlen(name) > 58) return -1;
    char header[512], dims[256] = "";
    long size = 1;
    for (int k = 0; k < ndim; k++) {
        size *= shape[k];
        const char *sep = ndim == 1 ? "," : k + 1 < ndim ? ", " : "";
        snprintf(dims + strlen(dims), sizeof dims - strlen(dims), "%ld%s", shape[k], sep);
    }
    int hlen = snprintf(header, sizeof header, "{'descr': '<f8', 'fortran_order': False, 'shape': (%s), }", dims);
    while ((10 + hlen + 1) % 64) header[hlen++] = ' ';           /* NPY 1.0: the data starts 64-byte aligned */
    header[hlen++] = '\n';
    size_t n = 10 + (size_t)hlen + 8 * (size_t)size;
    unsigned char *npy = malloc(n);
    if (!npy) return -1;
    memcpy(npy, "\x93NUMPY\x01\x00", 8);
    put16(npy + 8, (uint32_t)hlen);
    memcpy(npy + 10, header, (size_t)hlen);
    memcpy(npy + 10 + hlen, data, 8 * (size_t)size);
    FILE *fp = w->file;
    snprintf(w->names[w->n], sizeof w->names[0], "%s.npy", name);
    uint32_t nlen = (uint32_t)strlen(w->names[w->n]);
    w->offset[w->n] = (uint32_t)ftell(fp);
    w->crc[w->n] = crc32(npy, n);
    w->size[w->n] = (uint32_t)n;
    unsigned char h[30] = {0};
    put32(h, 0x04034b50); put16(h + 4, 20); put16(h + 12, 33);     /* version 2.0; 1980-01-01, as refsph */
    put32(h + 14, w->crc[w->n]); put32(h + 18, (uint32_t)n); put32(h + 22, (uint32_t)n); put16(h + 26, nlen);
    int ok = fwrite(h, 1, 30, fp) == 30 && fwrite(w->names[w->n], 1, nlen, fp) == nlen && fwrite(npy, 1, n, fp) == n;
    free(npy);
    w->n++;
    return ok ? 0 : -1;
}

int npz_end(npz_writer *w) {
    FILE *fp = w->file;
    uint32_t start = (uint32_t)ftell(fp);
    for (int k = 0; k < w->n; k++) {
        unsigned char c[46] = {0};
        uint32_t nlen = (uint32_t)strlen(w->names[k]);
        put32(c, 0x02014b50); put16(c + 4, 20); put16(c + 6, 20); put16(c + 14, 33);
        put32(c + 16, w->crc[k]); put32(c + 20, w->size[k]); put32(c + 24, w->size[k]); put16(c + 28, nlen);
        put32(c + 42, w->offset[k]);
        fwrite(c, 1, 46, fp);
        fwrite(w->names[k], 1, nlen, fp);
    }
    unsigned char e[22] = {0};
    put32(e, 0x06054b50); put16(e + 8, (uint32_t)w->n); put16(e + 10, (uint32_t)w->n);
    put32(e + 12, (uint32_t)ftell(fp) - start); put32(e + 16, start);
    fwrite(e, 1, 22, fp);
    return fclose(fp) == 0 ? 0 : -1;
}
