local w = asperity.world{simd = "avx9000"}
