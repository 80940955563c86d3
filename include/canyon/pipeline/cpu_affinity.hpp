#pragma once
// CPU affinity for the pipeline's stage threads (Linux: sched_getaffinity, pthread_setaffinity_np). CPUs are the
// kernel's logical CPU numbers, as in /proc/cpuinfo, taskset and `lscpu`.

#include <string>
#include <vector>

#include "canyon/core/result.hpp"

namespace canyon::pipeline {

/// The largest CPU number a set can name (the C library's CPU_SETSIZE - 1).
int max_cpu_number();
/// The CPUs this process may run on (its affinity mask, which taskset or a container may have narrowed), ascending.
std::vector<int> allowed_cpus();
/// The calling thread's CPUs, ascending.
std::vector<int> this_thread_cpus();
/// Restricts the calling thread to `cpus` (non-empty, each in 0..max_cpu_number()); an Error naming the CPUs and the
/// system's reason if the kernel refuses.
Status pin_this_thread(const std::vector<int>& cpus);
/// A CPU list in the kernel's notation: {0, 1, 2, 5} -> "0-2,5"; "" for none.
std::string cpu_list_text(const std::vector<int>& cpus);

}  // namespace canyon::pipeline
