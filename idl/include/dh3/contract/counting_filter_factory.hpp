#pragma once
// What dh3's content filter classes (the reply filter, the follow filter)
// share beside their own rule: counting what their filters decide, and
// deleting a filter as the type it was made as.

#include <atomic>
#include <cstdint>
#include <fastdds/dds/topic/IContentFilter.hpp>
#include <fastdds/dds/topic/IContentFilterFactory.hpp>

namespace dh3::contract {

/// Counts what the filters of one class in one participant decided.
struct FilterCounts {
  std::atomic<std::uint64_t> passed{0};
  std::atomic<std::uint64_t> rejected{0};

  void count(bool pass) { (pass ? passed : rejected).fetch_add(1, std::memory_order_relaxed); }
};

// Fast DDS's filter interfaces have no virtual destructor; a filter is only
// ever deleted as the `Filter` the factory made.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wnon-virtual-dtor"
/// A factory of `Filter`s that share its counts; it must outlive the
/// participant it is registered on.
template <class Filter>
class CountingFilterFactory : public eprosima::fastdds::dds::IContentFilterFactory {
 public:
  ReturnCode_t delete_content_filter(
      const char* /*filter_class_name*/,
      eprosima::fastdds::dds::IContentFilter* filter_instance) override {
    delete static_cast<Filter*>(filter_instance);
    return ReturnCode_t::RETCODE_OK;
  }

  [[nodiscard]] const FilterCounts& counts() const { return counts_; }

 protected:
  FilterCounts counts_;
};
#pragma GCC diagnostic pop

}  // namespace dh3::contract
