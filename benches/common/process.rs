//! What the benchmarks read of their own process on Linux (`/proc/self`): CPU time, page
//! faults and peak memory. Shared by the bench targets through `#[path]`; each function
//! returns `None` where `/proc` is missing or unreadable.

#![allow(dead_code)] // Each bench uses some of these.

/// The fields of `/proc/self/stat` after the command name (which is in parentheses and
/// may contain spaces): field N of the whole line is index N − 3 here.
fn stat_fields() -> Option<Vec<String>> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    let rest = stat.rsplit_once(')')?.1;
    Some(rest.split_whitespace().map(str::to_string).collect())
}

/// CPU seconds (user + system) used by this process so far.
pub fn cpu_seconds() -> Option<f64> {
    let fields = stat_fields()?;
    // utime and stime are fields 14 and 15 of the whole line, in clock ticks of 1/100 s.
    let utime: f64 = fields.get(11)?.parse().ok()?;
    let stime: f64 = fields.get(12)?.parse().ok()?;
    Some((utime + stime) / 100.0)
}

/// Minor page faults of this process so far: each is a fresh page the kernel had to
/// clear, which costs more than the work on it in a VM.
pub fn page_faults() -> Option<u64> {
    // minflt is field 10 of the whole line.
    stat_fields()?.get(7)?.parse().ok()
}

/// Peak resident memory of this process (`VmHWM`), MiB.
pub fn peak_mib() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb / 1024.0)
}
