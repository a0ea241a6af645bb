#pragma once
// Where the request side leaves its answers: the service's ReplyChannel, or a
// test's recorder. Each request gets exactly one reply through it.
//
// Threading: write() from any thread (request listeners, bus loops) at once;
// an implementation takes no lock of its callers'. Knows no Fast DDS.

#include "dh3/contract/dh3.h"

namespace dh3::dds {

class ReplySink {
 public:
  virtual ~ReplySink() = default;
  /// Writes (or holds, then writes) the reply; `reply` may be moved from.
  virtual void write(msg::CommandReply& reply) = 0;
  virtual void write(msg::GroupReply& reply) = 0;

 protected:
  ReplySink() = default;
  ReplySink(const ReplySink&) = default;
  ReplySink& operator=(const ReplySink&) = default;
};

}  // namespace dh3::dds
