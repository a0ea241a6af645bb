#pragma once
// The factory of each of dh3's content filter classes (the reply filter, the
// follow filter): what Fast DDS asks of a factory, for a Filter that says
// which expressions and parameters it takes, and the counts of what the
// class's filters decided.

#include <atomic>
#include <cstdint>
#include <fastdds/dds/topic/IContentFilter.hpp>
#include <fastdds/dds/topic/IContentFilterFactory.hpp>
#include <memory>

namespace dh3::contract {

/// A filter's parameters, as Fast DDS hands them over.
using FilterParameters = eprosima::fastdds::dds::IContentFilterFactory::ParameterSeq;

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
/// Makes `Filter`s, which share its counts; registered under the filter's
/// class on every dh3 participant (it must outlive the participant).
/// `Filter::make(expression, parameters, counts)` makes a filter, or nullptr
/// for an expression or parameters it does not take;
/// `filter.set_parameters(parameters)` takes new ones, or says false.
template <class Filter>
class CountingFilterFactory final : public eprosima::fastdds::dds::IContentFilterFactory {
 public:
  ReturnCode_t create_content_filter(
      const char* /*filter_class_name*/, const char* /*type_name*/,
      const eprosima::fastdds::dds::TopicDataType* /*data_type*/, const char* filter_expression,
      const ParameterSeq& filter_parameters,
      eprosima::fastdds::dds::IContentFilter*& filter_instance) override {
    if (filter_expression == nullptr) {  // new parameters for an existing filter
      if (filter_instance == nullptr) return ReturnCode_t::RETCODE_BAD_PARAMETER;
      return static_cast<Filter*>(filter_instance)->set_parameters(filter_parameters)
                 ? ReturnCode_t::RETCODE_OK
                 : ReturnCode_t::RETCODE_BAD_PARAMETER;
    }
    std::unique_ptr<Filter> made = Filter::make(filter_expression, filter_parameters, counts_);
    if (made == nullptr) return ReturnCode_t::RETCODE_BAD_PARAMETER;
    delete_content_filter(nullptr, filter_instance);
    filter_instance = made.release();
    return ReturnCode_t::RETCODE_OK;
  }

  ReturnCode_t delete_content_filter(
      const char* /*filter_class_name*/,
      eprosima::fastdds::dds::IContentFilter* filter_instance) override {
    delete static_cast<Filter*>(filter_instance);
    return ReturnCode_t::RETCODE_OK;
  }

  [[nodiscard]] const FilterCounts& counts() const { return counts_; }

 private:
  FilterCounts counts_;
};
#pragma GCC diagnostic pop

}  // namespace dh3::contract
