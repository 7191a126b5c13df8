#include "gvkit/codec/profile.hpp"

namespace gvkit::codec {

const char* profile_name(Profile profile) {
  switch (profile) {
    case Profile::kAuto:
      return "auto";
    case Profile::kLossless:
      return "lossless";
    case Profile::kIntra:
      return "intra";
    case Profile::kMain:
      return "main";
  }
  return "?";
}

Result<Profile> parse_profile(const std::string& name) {
  for (Profile p : {Profile::kAuto, Profile::kLossless, Profile::kIntra, Profile::kMain})
    if (name == profile_name(p)) return p;
  return invalid_argument("profile '" + name + "' unknown (auto, lossless, intra or main)");
}

Result<Profile> profile_from_idc(uint8_t idc) {
  if (idc >= static_cast<uint8_t>(Profile::kLossless) &&
      idc <= static_cast<uint8_t>(Profile::kMain))
    return static_cast<Profile>(idc);
  return unsupported("profile_idc " + std::to_string(idc) +
                     " unknown (format 2.0: 1 lossless, 2 intra, 3 main)");
}

}  // namespace gvkit::codec
