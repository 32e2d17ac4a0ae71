// The sampling jitter of a pixel (the scene's Sampling.jitter): a deterministic hash of the pixel and the frame
// seed to [0, 1), the same as the CPU ray caster's (_sample.jitter01). Included by the ray caster and the slicer.

float jitter01(int x, int y, int seed) {   // _sample.jitter01, in 32-bit unsigned arithmetic
    uint h = (uint(x) * 73856093u) ^ (uint(y) * 19349663u) ^ (uint(seed + 1) * 83492791u);
    h = (h ^ 61u) ^ (h >> 16);
    h = h + (h << 3);
    h ^= h >> 4;
    h = h * 0x27D4EB2Du;
    h ^= h >> 15;
    return float(h & 0xFFFFFFu) / 16777216.0;
}
