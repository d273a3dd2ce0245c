//! Runtime dispatch of hot loops to wider instruction sets, in one place.
//!
//! The workspace forbids `unsafe`, so hot loops are written for the compiler to vectorise and
//! compiled several times by the `multiversion` crate, which picks the best version the
//! processor supports when the function is first called. [`dispatched!`](crate::dispatched)
//! names the targets once for every such function: AVX-512 with BITALG (byte population counts),
//! AVX2, and the x86-64 baseline. Integer code gives the same results on every target; float
//! code too, because Rust never contracts a multiply and an add into one rounding.

/// Compiles the function it wraps for AVX-512 (with BITALG), AVX2 and the x86-64 baseline, and
/// calls the best one the processor supports (see the module documentation). The crate that
/// uses it must depend on `multiversion`.
#[macro_export]
macro_rules! dispatched {
    ($function:item) => {
        #[multiversion::multiversion(targets(
            "x86_64+avx512f+avx512bw+avx512vl+avx512bitalg+popcnt+bmi1+lzcnt",
            "x86_64+avx2+popcnt",
        ))]
        $function
    };
}
