// Importance sampling of VPLs from a table of candidate fluxes (RSM texels, or the cells of the
// IRSMs), shared by ism_vpl.comp and ism_bounce.comp. One workgroup of 256: each invocation sums a
// chunk into cdf[] (inclusive, local), a Hillis-Steele scan of the chunk sums makes the CDF
// global, then VPL i sits at u_i = (i + jitter_i) / N (stratified; fixed jitter per i, so a
// static scene gives the same VPLs every frame), found by binary search; its flux is the
// candidate's / (N pdf). An all-black table (sum 0: the empty CDF) places no VPL (guard).
#ifndef ISM_SAMPLE_GLSL
#define ISM_SAMPLE_GLSL

shared float ismPartial[256];

// Adds the scan of the 256 chunk sums to cdf[begin, end); returns the total.
float ismScan(float run, int begin, int end) {
  int t = int(gl_LocalInvocationID.x);
  ismPartial[t] = run;
  barrier();
  for (int off = 1; off < 256; off <<= 1) {
    float add = t >= off ? ismPartial[t - off] : 0.0;
    barrier();
    ismPartial[t] += add;
    barrier();
  }
  float base = t > 0 ? ismPartial[t - 1] : 0.0;
  for (int i = begin; i < end; ++i) cdf[i] += base;
  memoryBarrierBuffer();
  barrier();
  return ismPartial[255];
}

// Stratified target of VPL i of n: u_i sum, u_i = (i + jitter_i) / n.
float ismTarget(int i, int n, float sum) {
  float u = (float(i) + float(ismHash(uint(i) * 747796405u + 1u) >> 8) / 16777216.0) / float(n);
  return u * sum;
}

// The smallest j < total with cdf[j] > target (binary search).
int ismFind(float target, int total) {
  int lo = 0, hi = total - 1;
  while (lo < hi) {
    int mid = (lo + hi) / 2;
    if (cdf[mid] > target) hi = mid; else lo = mid + 1;
  }
  return lo;
}

// The candidate VPL i of n falls on (smallest j with cdf[j] > u sum); its probability in p.
int ismPick(int i, int n, int total, float sum, out float p) {
  int lo = ismFind(ismTarget(i, n, sum), total);
  p = (cdf[lo] - (lo > 0 ? cdf[lo - 1] : 0.0)) / sum;
  return lo;
}

#endif
