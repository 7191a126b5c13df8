#pragma once
// Heap settings for programs that process frame after frame: each frame allocates and frees
// the same large arrays (meshes, distance fields, index maps, several MB each). With glibc's
// defaults, arrays above the mmap threshold are mapped and unmapped every time, and freed memory
// at the top of the heap is returned to the system, so every frame pays the page faults of
// touching fresh pages again (about a tenth of the facemap clean stage's time at 255K vertices,
// docs/benchmarks.md). This keeps such arrays on the heap and freed memory in the process for
// reuse.

namespace gvkit {

// glibc: mmap threshold 32 MiB (its largest), trim threshold 256 MiB, so up to that much freed
// memory stays in the process. Other C libraries: does nothing. Returns whether the settings
// were applied. Call once, early (before threads start).
bool tune_allocator_for_frames();

}  // namespace gvkit
