// CPU affinity for stage threads (see cpu_affinity.hpp).

#include "canyon/pipeline/cpu_affinity.hpp"

#include <cstring>

#include <pthread.h>
#include <sched.h>

namespace canyon::pipeline {
namespace {

std::vector<int> cpus_of(const cpu_set_t& set) {
  std::vector<int> cpus;
  for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu) {
    if (CPU_ISSET(cpu, &set)) cpus.push_back(cpu);
  }
  return cpus;
}

}  // namespace

int max_cpu_number() {
  return CPU_SETSIZE - 1;
}

std::vector<int> allowed_cpus() {
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof(set), &set) != 0) return {};
  return cpus_of(set);
}

std::vector<int> this_thread_cpus() {
  cpu_set_t set;
  CPU_ZERO(&set);
  if (pthread_getaffinity_np(pthread_self(), sizeof(set), &set) != 0) return {};
  return cpus_of(set);
}

Status pin_this_thread(const std::vector<int>& cpus) {
  if (cpus.empty()) return Error{"no CPU to pin the thread to"};
  cpu_set_t set;
  CPU_ZERO(&set);
  for (const int cpu : cpus) {
    if (cpu < 0 || cpu > max_cpu_number()) {
      return Error{"CPU " + std::to_string(cpu) + " is out of range 0.." + std::to_string(max_cpu_number())};
    }
    CPU_SET(cpu, &set);
  }
  if (const int e = pthread_setaffinity_np(pthread_self(), sizeof(set), &set); e != 0) {
    return Error{"cannot run on CPUs " + cpu_list_text(cpus) + ": " + std::strerror(e)};
  }
  return Ok{};
}

std::string cpu_list_text(const std::vector<int>& cpus) {
  std::string text;
  for (std::size_t i = 0; i < cpus.size();) {
    std::size_t last = i;
    while (last + 1 < cpus.size() && cpus[last + 1] == cpus[last] + 1) ++last;
    if (!text.empty()) text += ',';
    text += std::to_string(cpus[i]);
    if (last > i) text += '-' + std::to_string(cpus[last]);
    i = last + 1;
  }
  return text;
}

}  // namespace canyon::pipeline
