// Ray and database-access statistics, as in the paper's Table 1.
// RayStats is a plain sum: counts from several tracers (or processors) merge
// with +=, and every ratio is computed from the sums when reported.
#pragma once

#include <cstdint>

namespace tracer {

struct RayStats {
  std::uint64_t primary = 0;        // eye rays (pixel centres, or corners in SPD mode)
  std::uint64_t primary_hits = 0;   // eye rays that hit an object
  std::uint64_t shadow = 0;
  std::uint64_t reflected = 0;
  std::uint64_t refracted = 0;
  std::uint64_t box_tests = 0;      // BVH child boxes tested, or grid cells read (not those skipped as empty)
  std::uint64_t prim_tests = 0;     // ray-primitive intersection tests
  std::uint64_t record_reads = 0;   // records (nodes, cells, primitives...) read from pages
  std::uint64_t page_calls = 0;     // PageSource::page() calls (reads outside the last page)
  std::uint64_t samples = 0;        // pixels or corner samples traced
  std::uint64_t distinct_pages = 0; // sum over samples of the distinct pages each touched

  std::uint64_t rays() const { return primary + shadow + reflected + refracted; }
  double pages_per_sample() const {
    return samples ? double(distinct_pages) / double(samples) : 0.0;
  }

  RayStats& operator+=(const RayStats& o) {
    primary += o.primary;
    primary_hits += o.primary_hits;
    shadow += o.shadow;
    reflected += o.reflected;
    refracted += o.refracted;
    box_tests += o.box_tests;
    prim_tests += o.prim_tests;
    record_reads += o.record_reads;
    page_calls += o.page_calls;
    samples += o.samples;
    distinct_pages += o.distinct_pages;
    return *this;
  }
};

}  // namespace tracer
