//! Settings of the command's whole process, made once at its start by the
//! command line (and by the bench's `command_cost`, which stands for the
//! command line's process). Not for a library's other callers (Python, C):
//! they own their process and its allocator.

/// glibc's threshold above which an allocation gets a mapping of its own,
/// handed back to the system when freed, B: 128 KiB, glibc's own initial
/// value (mallopt(3), `M_MMAP_THRESHOLD`). Set explicitly, it stays there:
/// left alone, glibc raises it to the size of every such block freed (up to
/// 32 MiB), after which the calibration's MB-sized vectors (smoothed
/// columns, checkpoints, corrected streams) come from the heaps, rayon's
/// threads' included, and what they free stays resident. Measured with
/// `command_cost` on the bench's simulated 10-minute and 1-hour drives
/// (docs/performance.md, "Sixth round"): the hour's peak RSS of `evaluate
/// --outage 30 --step 10` 158 → 116 MB and of `calibrate` 122 → 100 MB
/// (the heap's own peak unchanged), for about 4 % more CPU time on the
/// hour, all of it system time (+0.7–0.9 s: the mappings made and handed
/// back); the user time is the same within noise. Checked
/// there, not by a test (a process-wide setting of one C library).
pub const MMAP_THRESHOLD_B: i32 = 128 * 1024;

/// Fixes glibc's mmap threshold at [`MMAP_THRESHOLD_B`] so that large
/// blocks freed go back to the system instead of staying in the process's
/// peak (module docs). Returns whether it was set: `false` on other C
/// libraries and systems (nothing to do there), or where glibc refused.
pub fn return_large_blocks_when_freed() -> bool {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    {
        // SAFETY: mallopt only changes the allocator's parameters; it is
        // called with a documented parameter and a value in its range.
        unsafe { libc::mallopt(libc::M_MMAP_THRESHOLD, MMAP_THRESHOLD_B) == 1 }
    }
    #[cfg(not(all(target_os = "linux", target_env = "gnu")))]
    {
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_threshold_is_set_on_glibc_and_allocations_still_work() {
        let set = return_large_blocks_when_freed();
        assert_eq!(set, cfg!(all(target_os = "linux", target_env = "gnu")));
        // Blocks on both sides of the threshold, freed and made again.
        for n in [MMAP_THRESHOLD_B as usize / 2, 4 * MMAP_THRESHOLD_B as usize] {
            let v = vec![7u8; n];
            assert_eq!(v.iter().map(|&b| b as usize).sum::<usize>(), 7 * n);
        }
    }
}
