#pragma once
// A test seam, not part of what the service offers: the points on a command
// request's way through the service that the service overhead benchmark
// (tests/bench/bench_round_trip.cpp) timestamps through
// ServiceOptions::test_seam_tracer. dh3-service never sets it.

#include <cstdint>
#include <functional>

namespace dh3::dds {

enum class TracePoint : std::uint8_t {
  request_taken,  ///< the request sample was taken from the reader
  reply_writing,  ///< its reply is about to be written
  reply_written,  ///< the reply writer's write() returned
};
using RequestTracer = std::function<void(TracePoint, std::uint64_t request_seq)>;

}  // namespace dh3::dds
