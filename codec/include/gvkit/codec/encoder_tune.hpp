#pragma once
// Tune keys: the encoder's per-tool switches and fine settings (EncoderOptions) by name, for
// experiments. One table, shared by `gvkit encode --tune key=value` and the Python module's
// encode(tune={...}); docs/encoding.md lists it. A user never needs them: the defaults are the
// best measured settings, and every combination still writes a valid format 2.0 stream.

#include <string>
#include <vector>

#include "gvkit/codec/encoder_options.hpp"
#include "gvkit/core/status.hpp"

namespace gvkit::codec {

struct TuneKey {
  const char* name;    // e.g. "merge"
  const char* values;  // what it takes, e.g. "on|off" or "0..32"
  const char* help;    // one line: what it changes (and whether only the encoder's decisions)
};

// Every key, in the order of docs/encoding.md.
const std::vector<TuneKey>& tune_keys();

// Sets the option named `key` from `value`: booleans take on/off, true/false, yes/no or 1/0,
// numbers their decimal form, enumerations their names, plane-qp-offsets three integers "X,Y,Z".
// invalid_argument naming the key and value when the key is unknown or the value does not parse
// ("tune merge=maybe: not on or off"); ranges are EncoderOptions::check()'s to report.
Status apply_tune(const std::string& key, const std::string& value, EncoderOptions* options);
// The same for "key=value".
Status apply_tune(const std::string& key_value, EncoderOptions* options);

}  // namespace gvkit::codec
