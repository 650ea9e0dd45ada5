/* Times the reference LWPR library (Klanke & Vijayakumar) on the streams streams.py writes (those of `cerebx bench --lwpr`):
   updates one sample at a time, best of five fresh models; then the nMSE on the test set and the number of RFs. */
#include <lwpr.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
static double now(void) { struct timespec t; clock_gettime(CLOCK_MONOTONIC, &t); return t.tv_sec + 1e-9 * t.tv_nsec; }
static double cpu(void) { struct timespec t; clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t); return t.tv_sec + 1e-9 * t.tv_nsec; }
int main(int argc, char **argv) {
  FILE *f = fopen(argv[1], "rb"); int h[4]; double p[4];
  fread(h, sizeof(int), 4, f); fread(p, sizeof(double), 4, f);
  int n = h[0], d = h[1], nt = h[2];
  double *x = malloc(sizeof(double) * n * d), *y = malloc(sizeof(double) * n), *xt = malloc(sizeof(double) * nt * d), *yt = malloc(sizeof(double) * nt);
  fread(x, sizeof(double), n * d, f); fread(y, sizeof(double), n, f); fread(xt, sizeof(double), nt * d, f); fread(yt, sizeof(double), nt, f);
  double best_w = 1e9, best_c = 1e9; int rfs = 0; double nmse = 0;
  for (int rep = 0; rep < 5; rep++) {
    LWPR_Model m; lwpr_init_model(&m, d, 1, "bench");
    lwpr_set_init_D_spherical(&m, p[0]); lwpr_set_init_alpha(&m, p[1]);
    if (p[2] >= 0) m.w_gen = p[2];
    if (p[3] >= 0) m.penalty = p[3];
    double yp, t0 = now(), c0 = cpu();
    for (int i = 0; i < n; i++) lwpr_update(&m, x + i * d, y + i, &yp, NULL);
    double w = now() - t0, c = cpu() - c0;
    if (w < best_w) best_w = w; if (c < best_c) best_c = c;
    double se = 0, mean = 0, var = 0;
    for (int i = 0; i < nt; i++) mean += yt[i] / nt;
    for (int i = 0; i < nt; i++) { double o; lwpr_predict(&m, xt + i * d, 0.001, &o, NULL, NULL); se += (o - yt[i]) * (o - yt[i]); var += (yt[i] - mean) * (yt[i] - mean); }
    nmse = se / var; rfs = m.sub[0].numRFS;
    lwpr_free_model(&m);
  }
  printf("{\"updates\": %d, \"receptive_fields\": %d, \"nmse\": %.4f, \"updates_per_s_wall\": %.0f, \"updates_per_cpu_s\": %.0f}\n", n, rfs, nmse, n / best_w, n / best_c);
  return 0;
}
