//! The engine thread's scheduling (issue 18, docs/performance.md): a
//! SCHED_FIFO priority so that HTTP, protocol and historian threads cannot
//! delay a scan, a CPU of its own, and memory locked against paging. Each
//! is optional (`[runtime] priority`, `cpu`, `lock_memory` in alba.toml) and
//! falls back to normal scheduling with one warning where the system does
//! not allow it (an unprivileged user without `CAP_SYS_NICE` or an rtprio
//! limit, a container).

/// What to ask for.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Realtime {
    /// SCHED_FIFO priority 1 to 99; 0 keeps normal scheduling.
    pub priority: u8,
    /// Run on this CPU only.
    pub cpu: Option<usize>,
    /// Lock the process's memory (current and future) in RAM.
    pub lock_memory: bool,
}

impl Realtime {
    /// Applies the settings to the calling thread (and, for memory, the
    /// process). Returns what could not be done, one sentence each.
    pub fn apply(&self) -> Vec<String> {
        let mut warnings = Vec::new();
        if self.priority > 0
            && let Err(e) = fifo(self.priority)
        {
            warnings.push(format!(
                "the engine thread runs at normal priority: SCHED_FIFO {} was refused ({e}); \
                 run as root, give the binary CAP_SYS_NICE, or raise the rtprio limit",
                self.priority
            ));
        }
        if let Some(cpu) = self.cpu {
            let mut set = rustix::thread::CpuSet::new();
            if cpu >= rustix::thread::CpuSet::MAX_CPU {
                warnings.push(format!("cpu = {cpu} is beyond the CPUs this system can name"));
            } else {
                set.set(cpu);
                if let Err(e) = rustix::thread::sched_setaffinity(None, &set) {
                    warnings.push(format!("the engine thread is not pinned to CPU {cpu}: {e}"));
                }
            }
        }
        if self.lock_memory {
            let flags = rustix::mm::MlockAllFlags::CURRENT | rustix::mm::MlockAllFlags::FUTURE;
            if let Err(e) = rustix::mm::mlockall(flags) {
                warnings.push(format!(
                    "memory is not locked ({e}): raise the memlock limit or run as root"
                ));
            }
        }
        warnings
    }

    /// `SCHED_FIFO 80, CPU 1, memory locked` (what was asked), for reports.
    pub fn describe(&self) -> String {
        let mut parts = vec![if self.priority > 0 {
            format!("SCHED_FIFO {}", self.priority)
        } else {
            "normal priority".to_string()
        }];
        if let Some(c) = self.cpu {
            parts.push(format!("CPU {c}"));
        }
        if self.lock_memory {
            parts.push("memory locked".into());
        }
        parts.join(", ")
    }
}

/// Undoes `lock_memory` for the whole process (benchmarks that compare
/// with and without it in one process).
pub fn unlock_memory() {
    let _ = rustix::mm::munlockall();
}

fn fifo(priority: u8) -> Result<(), String> {
    use thread_priority::{
        RealtimeThreadSchedulePolicy, ThreadPriority, ThreadPriorityValue, ThreadSchedulePolicy,
        set_thread_priority_and_policy, thread_native_id,
    };
    let value = ThreadPriorityValue::try_from(priority.min(99)).map_err(|e| e.to_string())?;
    set_thread_priority_and_policy(
        thread_native_id(),
        ThreadPriority::Crossplatform(value),
        ThreadSchedulePolicy::Realtime(RealtimeThreadSchedulePolicy::Fifo),
    )
    .map_err(|e| format!("{e:?}"))
}
