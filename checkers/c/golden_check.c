/* golden_check: an independent checker of refsph's golden cases, written from golden/FORMAT.md (version 2) and the
 * paper's equations alone (Islam, Bansal & Peng: Eq. (9) the cubic spline, Eqs. (10)-(14), (20)-(24) ESPH).
 *
 * It reads GOLDEN/<case>/input.npz with its own zip/NPY reader (npz.c), computes the case, and writes
 * OUT/<case>/output.npz, which `refsph compare GOLDEN OUT --only CASE...` then checks against refsph's numbers.
 *
 *   cc -std=c99 -O2 -o golden_check golden_check.c npz.c -lm
 *   ./golden_check [--plant BUG] GOLDEN OUT CASE...
 *
 * Cases it knows (by their case.json "kind"): kernel (kernel_cubic_2d, kernel_cubic_3d), esph_rates (esph_rates,
 * esph_rates_no_viscosity, esph_rates_no_artificial_pressure, esph_rates_stress_only), esph_pair_terms.
 * --plant BUG computes a deliberately wrong term, to show that `refsph compare` names it:
 *   separating-viscosity   pi_ij also on separating pairs (v_ij . x_ij > 0), against Eq. (12)
 *   support-h              the kernel cut off at r = h instead of 2h, against Eq. (9)
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "npz.h"

#define PI 3.14159265358979323846

typedef struct {
    int separating_viscosity;   /* the planted bugs (--plant); 0: the equations as written */
    int support_h;
} Options;

typedef struct {                /* what the cases read, and the message of the first error */
    char dir[1024];
    char err[2048];
} Case;

static void die(const char *msg) {
    fprintf(stderr, "golden_check: %s\n", msg);
    exit(2);
}

static npy_array get(Case *c, const char *name, char kind, int ndim) {
    npy_array a;
    char path[1100];
    snprintf(path, sizeof path, "%s/input.npz", c->dir);
    if (npz_read(path, name, &a, c->err, sizeof c->err) != 0) die(c->err);
    if (a.kind != kind || (ndim >= 0 && a.ndim != ndim)) {
        snprintf(c->err, sizeof c->err, "%s/%s: expected kind %c with %d dimensions", c->dir, name, kind, ndim);
        die(c->err);
    }
    return a;
}

static double number(Case *c, const char *name) {
    npy_array a = get(c, name, 'f', 0);
    double v = a.f[0];
    npy_free(&a);
    return v;
}

/* The case.json text; the kind it declares must be `kind` (the conventions the code below implements). */
static void check_kind(const char *dir, const char *kind) {
    char path[1100], want[128], *text = calloc(1, 1 << 20);
    snprintf(path, sizeof path, "%s/case.json", dir);
    FILE *f = fopen(path, "rb");
    if (!f || !text) die("cannot read case.json");
    size_t n = fread(text, 1, (1 << 20) - 1, f);
    fclose(f);
    text[n] = 0;
    snprintf(want, sizeof want, "\"kind\": \"%s\"", kind);
    if (!strstr(text, want) || !strstr(text, "\"format_version\": 2")) die("case.json: not this kind, or not format 2");
    free(text);
}

/* Eq. (9): the cubic B-spline W(r, h) and dW/dr in d dimensions; support 2h (h with the planted bug). */
static void cubic(double r, double h, int d, const Options *o, double *w, double *dwdr) {
    double q = r / h, alpha = d == 2 ? 10.0 / (7.0 * PI * h * h) : 1.0 / (PI * h * h * h);
    double qmax = o->support_h ? 1.0 : 2.0;
    if (q <= 1.0 && q <= qmax) {
        *w = alpha * (1.0 - 1.5 * q * q + 0.75 * q * q * q);
        *dwdr = alpha / h * (-3.0 * q + 2.25 * q * q);
    } else if (q <= qmax) {
        double t = 2.0 - q;
        *w = alpha * 0.25 * t * t * t;
        *dwdr = -alpha / h * 0.75 * t * t;
    } else {
        *w = 0.0;
        *dwdr = 0.0;
    }
}

static void write_case(const char *out_dir, const char *name, int n, const char **names, double **data,
                       const int *ndims, long shapes[][3]) {
    char path[1100];
    snprintf(path, sizeof path, "%s/%s", out_dir, name);
    mkdir(out_dir, 0777);
    mkdir(path, 0777);
    snprintf(path, sizeof path, "%s/%s/output.npz", out_dir, name);
    npz_writer w;
    if (npz_begin(&w, path) != 0) die("cannot write output.npz");
    for (int k = 0; k < n; k++)
        if (npz_add(&w, names[k], data[k], ndims[k], shapes[k]) != 0) die("cannot write an array");
    if (npz_end(&w) != 0) die("cannot close output.npz");
}

/* kernel_cubic_{2d,3d}: W(r) and dW/dr at the sample distances r, grad_i W(x_ij) = dW/dr x_ij / r. */
static void kernel_case(Case *c, const char *out, const char *name, const Options *o) {
    check_kind(c->dir, "kernel");
    npy_array r = get(c, "r", 'f', 1), x = get(c, "x_ij", 'f', 2);
    double h = number(c, "h");
    long m = x.shape[0], d = x.shape[1];
    double *W = malloc(r.size * sizeof *W), *dW = malloc(r.size * sizeof *dW), *g = malloc(x.size * sizeof *g);
    for (long k = 0; k < r.size; k++) cubic(r.f[k], h, (int)d, o, &W[k], &dW[k]);
    for (long k = 0; k < m; k++) {
        double rr = 0.0, w, dwdr;
        for (long a = 0; a < d; a++) rr += x.f[k * d + a] * x.f[k * d + a];
        rr = sqrt(rr);
        cubic(rr, h, (int)d, o, &w, &dwdr);
        for (long a = 0; a < d; a++) g[k * d + a] = rr > 0.0 ? dwdr / rr * x.f[k * d + a] : 0.0;
    }
    const char *names[] = {"W", "dW_dr", "grad_W"};
    double *data[] = {W, dW, g};
    int ndims[] = {1, 1, 2};
    long shapes[3][3] = {{r.size}, {r.size}, {m, d}};
    write_case(out, name, 3, names, data, ndims, shapes);
    free(W); free(dW); free(g); npy_free(&r); npy_free(&x);
}

/* ESPH (Eqs. (9)-(14), (20)-(24)) over the half pairs I < J of the input: the rates of esph_rates* or, with
 * pair_terms, the terms of each pair (esph_pair_terms). Every pair term goes to i and, with its sign, to j. */
static void esph_case(Case *c, const char *out, const char *name, int pair_terms, const Options *o) {
    check_kind(c->dir, pair_terms ? "esph_pair_terms" : "esph_rates");
    npy_array x = get(c, "x", 'f', 2), v = get(c, "v", 'f', 2), m = get(c, "m", 'f', 1), rho = get(c, "rho", 'f', 1);
    npy_array S = get(c, "S", 'f', 3), I = get(c, "I", 'i', 1), J = get(c, "J", 'i', 1);
    double h = number(c, "h"), dp = number(c, "dp"), beta1 = number(c, "beta1"), beta2 = number(c, "beta2");
    double gamma = number(c, "gamma"), n_ap = number(c, "n_ap"), eps = number(c, "eps");
    double rho0 = number(c, "rho0"), E = number(c, "E"), nu = number(c, "nu");
    long n = x.shape[0], d = x.shape[1], P = I.size;
    if (d != 2 && d != 3) die("x must have 2 or 3 columns");
    double K = E / (3.0 * (1.0 - 2.0 * nu)), G = E / (2.0 * (1.0 + nu)), c0 = sqrt(E / rho0);   /* Eq. (24) */
    double Wdp, unused;
    cubic(dp, h, (int)d, o, &Wdp, &unused);
    double *p = malloc(n * sizeof *p);
    for (long i = 0; i < n; i++) p[i] = K * (rho.f[i] / rho0 - 1.0);                            /* Eq. (24) */
    double *rho_dot = calloc(n, sizeof *rho_dot), *acc = calloc(n * d, sizeof *acc);
    double *l = calloc(n * d * d, sizeof *l);
    double *pr = malloc(P * sizeof *pr), *pW = malloc(P * sizeof *pW), *pdW = malloc(P * sizeof *pdW);
    double *pg = malloc(P * d * sizeof *pg), *ppi = malloc(P * sizeof *ppi), *ppa = malloc(P * sizeof *ppa);
    for (long k = 0; k < P; k++) {
        long i = (long)I.i[k], j = (long)J.i[k];
        if (!(0 <= i && i < j && j < n)) die("pairs must be half pairs I < J < N");
        double dx[3], dv[3], g[3], r2 = 0.0, vr = 0.0, vg = 0.0, w, dwdr;
        for (long a = 0; a < d; a++) {
            dx[a] = x.f[i * d + a] - x.f[j * d + a];
            dv[a] = v.f[i * d + a] - v.f[j * d + a];
            r2 += dx[a] * dx[a];
            vr += dv[a] * dx[a];
        }
        double r = sqrt(r2);
        cubic(r, h, (int)d, o, &w, &dwdr);
        for (long a = 0; a < d; a++) {
            g[a] = r > 0.0 ? dwdr / r * dx[a] : 0.0;                       /* grad_i W_ij */
            vg += dv[a] * g[a];
        }
        double pi = 0.0;                                                    /* Eqs. (12)-(13) */
        if (vr <= 0.0 || o->separating_viscosity) {
            double mu = h * vr / (r2 + eps * h * h);
            pi = (-beta1 * c0 * mu + beta2 * mu * mu) / (0.5 * (rho.f[i] + rho.f[j]));
        }
        double pa = 0.0;                                                    /* Eq. (14) */
        if (!(p[i] > 0.0 && p[j] > 0.0))
            pa = gamma * (fabs(p[i]) / (rho.f[i] * rho.f[i]) + fabs(p[j]) / (rho.f[j] * rho.f[j])) * pow(w / Wdp, n_ap);
        pr[k] = r; pW[k] = w; pdW[k] = dwdr; ppi[k] = pi; ppa[k] = pa;
        for (long a = 0; a < d; a++) pg[k * d + a] = g[a];
        rho_dot[i] += m.f[j] * vg;                                          /* Eq. (10) */
        rho_dot[j] += m.f[i] * vg;
        for (long a = 0; a < d; a++) {
            double fa = 0.0;                                                /* Eq. (11): the bracket times grad W */
            for (long b = 0; b < d; b++) {
                l[(i * d + a) * d + b] -= m.f[j] / rho.f[j] * dv[a] * g[b];  /* Eq. (23) */
                l[(j * d + a) * d + b] -= m.f[i] / rho.f[i] * dv[a] * g[b];
                double si = (S.f[(i * d + a) * d + b] - (a == b ? p[i] : 0.0)) / (rho.f[i] * rho.f[i]);
                double sj = (S.f[(j * d + a) * d + b] - (a == b ? p[j] : 0.0)) / (rho.f[j] * rho.f[j]);
                fa += (si + sj - (a == b ? pi + pa : 0.0)) * g[b];
            }
            acc[i * d + a] += m.f[j] * fa;
            acc[j * d + a] -= m.f[i] * fa;
        }
    }
    if (pair_terms) {
        const char *names[] = {"r", "W", "dW_dr", "grad_W", "pi", "p_a", "p"};
        double *data[] = {pr, pW, pdW, pg, ppi, ppa, p};
        int ndims[] = {1, 1, 1, 2, 1, 1, 1};
        long shapes[7][3] = {{P}, {P}, {P}, {P, d}, {P}, {P}, {n}};
        write_case(out, name, 7, names, data, ndims, shapes);
    } else {
        double *dS = malloc(n * d * d * sizeof *dS), *dSzz = malloc(n * sizeof *dSzz);
        for (long i = 0; i < n; i++) {                                      /* Eqs. (20)-(22), Jaumann */
            const double *L = l + i * d * d, *Si = S.f + i * d * d;
            double tr = 0.0;
            for (long a = 0; a < d; a++) tr += L[a * d + a];
            for (long a = 0; a < d; a++)
                for (long b = 0; b < d; b++) {
                    double e = 0.5 * (L[a * d + b] + L[b * d + a]), rot = 0.0;
                    for (long q = 0; q < d; q++) {
                        double om_aq = 0.5 * (L[a * d + q] - L[q * d + a]), om_qb = 0.5 * (L[q * d + b] - L[b * d + q]);
                        rot += om_aq * Si[q * d + b] - Si[a * d + q] * om_qb;
                    }
                    dS[(i * d + a) * d + b] = 2.0 * G * (e - (a == b ? tr / 3.0 : 0.0)) + rot;
                }
            dSzz[i] = d == 2 ? -2.0 * G / 3.0 * tr : 0.0;                   /* plane strain */
        }
        const char *names[] = {"rho_dot", "v_dot", "S_dot", "S_zz_dot", "l"};
        double *data[] = {rho_dot, acc, dS, dSzz, l};
        int ndims[] = {1, 2, 3, 1, 3};
        long shapes[5][3] = {{n}, {n, d}, {n, d, d}, {n}, {n, d, d}};
        write_case(out, name, 5, names, data, ndims, shapes);
        free(dS); free(dSzz);
    }
    free(p); free(rho_dot); free(acc); free(l); free(pr); free(pW); free(pdW); free(pg); free(ppi); free(ppa);
    npy_free(&x); npy_free(&v); npy_free(&m); npy_free(&rho); npy_free(&S); npy_free(&I); npy_free(&J);
}

int main(int argc, char **argv) {
    Options o = {0, 0};
    int k = 1;
    uint16_t probe = 1;
    if (*(unsigned char *)&probe != 1) die("a little-endian machine is needed (the NPY data are read as they lie)");
    if (k + 1 < argc && strcmp(argv[k], "--plant") == 0) {
        if (strcmp(argv[k + 1], "separating-viscosity") == 0) o.separating_viscosity = 1;
        else if (strcmp(argv[k + 1], "support-h") == 0) o.support_h = 1;
        else die("--plant: separating-viscosity or support-h");
        k += 2;
    }
    if (argc - k < 3) die("usage: golden_check [--plant BUG] GOLDEN OUT CASE...");
    const char *golden = argv[k], *out = argv[k + 1];
    for (k += 2; k < argc; k++) {
        Case c;
        snprintf(c.dir, sizeof c.dir, "%s/%s", golden, argv[k]);
        if (strncmp(argv[k], "kernel_cubic_", 13) == 0) kernel_case(&c, out, argv[k], &o);
        else if (strcmp(argv[k], "esph_pair_terms") == 0) esph_case(&c, out, argv[k], 1, &o);
        else if (strncmp(argv[k], "esph_rates", 10) == 0) esph_case(&c, out, argv[k], 0, &o);
        else die("unknown case (kernel_cubic_*, esph_rates*, esph_pair_terms)");
        printf("%s: written to %s/%s/output.npz\n", argv[k], out, argv[k]);
    }
    return 0;
}
