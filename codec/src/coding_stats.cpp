#include "gvkit/codec/coding_stats.hpp"

namespace gvkit::codec {

const char* syntax_group_name(int group) {
  static const char* const kNames[kSyntaxGroupCount] = {"mb_type", "motion",  "modes",
                                                        "cbp",     "sig_map", "levels"};
  return group >= 0 && group < kSyntaxGroupCount ? kNames[group] : "?";
}

double PlaneCodingStats::total_bits() const {
  double sum = 0;
  for (double b : bits) sum += b;
  return sum;
}

PlaneCodingStats& PlaneCodingStats::operator+=(const PlaneCodingStats& other) {
  for (int g = 0; g < kSyntaxGroupCount; ++g) bits[g] += other.bits[g];
  intra_mbs += other.intra_mbs;
  inter_mbs += other.inter_mbs;
  td_mbs += other.td_mbs;
  td16_mbs += other.td16_mbs;
  quadratic_mbs += other.quadratic_mbs;
  skip_mbs += other.skip_mbs;
  merge_skip_mbs += other.merge_skip_mbs;
  merged_mbs += other.merged_mbs;
  transform8_mbs += other.transform8_mbs;
  transform16_mbs += other.transform16_mbs;
  for (int i = 0; i < 9; ++i) cross_scale_mbs[i] += other.cross_scale_mbs[i];
  for (int i = 0; i < 4; ++i) partition_mbs[i] += other.partition_mbs[i];
  return *this;
}

}  // namespace gvkit::codec
