/* npz.h: read and write the arrays of refsph's golden cases (golden/FORMAT.md, version 2) without any library.
 *
 * An .npz file is a zip archive of .npy files. The golden cases store them uncompressed (np.savez, not
 * np.savez_compressed), so a reader needs no inflate: it walks the zip's local file headers and parses the NPY
 * header of the entry it wants. Only what the format allows is accepted: NPY 1.0-3.0, dtype '<f8' or '<i8',
 * fortran_order False, any shape (0-d included). Anything else is an error with a message, never a guess.
 */
#ifndef REFSPH_NPZ_H
#define REFSPH_NPZ_H

#include <stddef.h>
#include <stdint.h>

#define NPY_MAX_DIM 8

typedef struct {
    int ndim;
    long shape[NPY_MAX_DIM];
    long size;          /* number of elements: the product of shape (1 for a 0-d array) */
    char kind;          /* 'f': float64 (data in f), 'i': int64 (data in i) */
    double *f;
    int64_t *i;
} npy_array;

/* Read array `name` (without ".npy") from the .npz file `path` into `out` (free it with npy_free).
 * Returns 0, or -1 with a message in err (errlen bytes). */
int npz_read(const char *path, const char *name, npy_array *out, char *err, size_t errlen);
void npy_free(npy_array *a);

/* Write float64 arrays into a new uncompressed .npz file: npz_begin, npz_add per array, npz_end. */
typedef struct {
    void *file;
    int n;
    char names[64][64];
    uint32_t crc[64], size[64], offset[64];
} npz_writer;

int npz_begin(npz_writer *w, const char *path);
int npz_add(npz_writer *w, const char *name, const double *data, int ndim, const long *shape);
int npz_end(npz_writer *w);

#endif
