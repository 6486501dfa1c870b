//! Times as people give them (milliseconds, on the command line and in reports) and as
//! the suite counts them (microseconds).

/// `ms` milliseconds in whole microseconds (negative: 0).
pub fn ms_to_us(ms: f64) -> u64 {
    (ms * 1000.0).round().max(0.0) as u64
}
