/* Triangle (Shewchuk), compiled from its own source, timed in-process.
 *
 *   triangle_driver SWITCHES POINTS.npy [--out TRIANGLES.npy]
 *
 * SWITCHES: "" (divide and conquer), "i" (incremental) or "F" (sweepline);
 * we add "zQNBP" (number from zero, quiet, no node, boundary or segment
 * output).  POINTS.npy: float64 (n, 2), C order.  Only triangulate() is
 * timed (wall clock and TSC); file I/O is outside.  The build inserts two
 * counters into Triangle's source without touching its arithmetic:
 * lfqt_orient_undecided and lfqt_incircle_undecided count the calls that
 * its stage-1 filter leaves to counterclockwiseadapt / incircleadapt
 * (paper 1, Table 1); lfqt_orient_calls and lfqt_incircle_calls all calls.
 * Prints one JSON line.
 */
#define _POSIX_C_SOURCE 200809L
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>
#include <x86intrin.h>

#include "triangle.h"

extern long lfqt_orient_calls, lfqt_orient_undecided, lfqt_incircle_calls,
    lfqt_incircle_undecided;

static void die(const char *msg, const char *arg) {
  fprintf(stderr, "triangle_driver: %s%s\n", msg, arg ? arg : "");
  exit(1);
}

/* The data of a float64 (n, 2) C-order .npy file; n through *rows. */
static double *read_points(const char *path, long *rows) {
  FILE *f = fopen(path, "rb");
  if (!f) die("cannot open ", path);
  unsigned char magic[8];
  if (fread(magic, 1, 8, f) != 8 || memcmp(magic, "\x93NUMPY", 6) != 0)
    die("not a .npy file: ", path);
  uint32_t hlen = 0;
  if (magic[6] == 1) {
    uint16_t h16;
    if (fread(&h16, 2, 1, f) != 1) die("truncated header: ", path);
    hlen = h16;
  } else if (fread(&hlen, 4, 1, f) != 1) {
    die("truncated header: ", path);
  }
  char *header = calloc(hlen + 1, 1);
  if (!header || fread(header, 1, hlen, f) != hlen) die("truncated header: ", path);
  if (!strstr(header, "'<f8'")) die("points must be float64: ", path);
  if (strstr(header, "'fortran_order': True")) die("Fortran order is not supported: ", path);
  char *shape = strstr(header, "'shape': (");
  long n = 0, d = 0;
  if (!shape || sscanf(shape, "'shape': (%ld, %ld)", &n, &d) != 2 || d != 2)
    die("points must have shape (n, 2): ", path);
  free(header);
  double *xy = malloc((size_t)(2 * n + 1) * sizeof(double));
  if (!xy || fread(xy, sizeof(double), (size_t)(2 * n), f) != (size_t)(2 * n))
    die("truncated data: ", path);
  fclose(f);
  *rows = n;
  return xy;
}

static void write_triangles(const char *path, const int *tri, long m) {
  FILE *f = fopen(path, "wb");
  if (!f) die("cannot write ", path);
  char header[128];
  int len = snprintf(header, sizeof header,
                     "{'descr': '<i8', 'fortran_order': False, 'shape': (%ld, 3), }", m);
  while ((10 + len + 1) % 64 != 0) header[len++] = ' ';
  header[len++] = '\n';
  uint16_t hl = (uint16_t)len;
  fwrite("\x93NUMPY\x01\x00", 1, 8, f);
  fwrite(&hl, 2, 1, f);
  fwrite(header, 1, (size_t)len, f);
  for (long k = 0; k < 3 * m; ++k) {
    int64_t v = tri[k];
    fwrite(&v, sizeof v, 1, f);
  }
  fclose(f);
}

static long resident_bytes(void) {
  long pages = 0, resident = 0;
  FILE *f = fopen("/proc/self/statm", "r");
  if (f) {
    if (fscanf(f, "%ld %ld", &pages, &resident) != 2) resident = 0;
    fclose(f);
  }
  return resident * 4096L;
}

int main(int argc, char **argv) {
  if (argc < 3) die("usage: triangle_driver SWITCHES POINTS.npy [--out TRIANGLES.npy]", NULL);
  const char *algorithm = argv[1], *out_path = NULL;
  if (strspn(algorithm, "iF") != strlen(algorithm) || strlen(algorithm) > 1)
    die("SWITCHES must be \"\", \"i\" or \"F\", not ", algorithm);
  for (int k = 3; k < argc; ++k) {
    if (strcmp(argv[k], "--out") == 0 && k + 1 < argc) out_path = argv[++k];
    else die("unknown argument ", argv[k]);
  }
  long n = 0;
  double *xy = read_points(argv[2], &n);
  char switches[16];
  snprintf(switches, sizeof switches, "zQNBP%s", algorithm);
  struct triangulateio in, out;
  memset(&in, 0, sizeof in);
  memset(&out, 0, sizeof out);
  in.pointlist = xy;
  in.numberofpoints = (int)n;
  long baseline = resident_bytes();
  struct timespec t0, t1;
  clock_gettime(CLOCK_MONOTONIC, &t0);
  unsigned long long c0 = __rdtsc();
  triangulate(switches, &in, &out, NULL);
  unsigned long long c1 = __rdtsc();
  clock_gettime(CLOCK_MONOTONIC, &t1);
  double seconds = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
  struct rusage ru;
  getrusage(RUSAGE_SELF, &ru);
  if (out_path) write_triangles(out_path, out.trianglelist, out.numberoftriangles);
  printf("{\"n\": %ld, \"switches\": \"%s\", \"seconds\": %.9f, \"tsc_cycles\": %llu, "
         "\"triangles\": %d, \"orientation_tests\": %ld, \"orientation_stage1_undecided\": %ld, "
         "\"incircle_tests\": %ld, \"incircle_stage1_undecided\": %ld, "
         "\"baseline_rss_bytes\": %ld, \"peak_rss_bytes\": %ld}\n",
         n, switches, seconds, c1 - c0, out.numberoftriangles, lfqt_orient_calls,
         lfqt_orient_undecided, lfqt_incircle_calls, lfqt_incircle_undecided, baseline,
         ru.ru_maxrss * 1024L);
  free(out.trianglelist);
  free(xy);
  return 0;
}
