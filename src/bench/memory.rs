//! The process's resident memory, from Linux's `/proc/self/status`: the peak (`VmHWM`) and
//! its reset (writing 5 to `/proc/self/clear_refs`), so that each benchmark reports its own
//! peak. Elsewhere both return `None`.

/// Peak resident set size since the start or the last [`reset_peak`] (bytes).
pub fn peak_rss() -> Option<u64> {
    status_kib("VmHWM:").map(|k| k * 1024)
}

/// Resident set size now (bytes).
pub fn current_rss() -> Option<u64> {
    status_kib("VmRSS:").map(|k| k * 1024)
}

/// Resets the peak to the current resident size; false where the system does not allow it.
pub fn reset_peak() -> bool {
    std::fs::write("/proc/self/clear_refs", "5").is_ok()
}

fn status_kib(key: &str) -> Option<u64> {
    let text = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = text.lines().find(|l| l.starts_with(key))?;
    line[key.len()..].trim().trim_end_matches("kB").trim().parse().ok()
}
