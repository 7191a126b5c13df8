// The gvkit Python module (pybind11): geometry videos (.gvid) as numpy arrays.
//
//   import gvkit
//   r = gvkit.open("face.gvid")      # format 2.0, or a legacy 1.x stream
//   r.info                            # dict: width, height, fps, bit_depth, frames, format, ...
//   xyz, valid = r.read(0)            # (H, W, 3) float32 mm, (H, W) bool domain mask
//   xyz_all, valid = r.read_all()     # (N, H, W, 3), (H, W)
//   s = r.stats()                     # numpy arrays per frame: bits, type, qp, ...
//   gvkit.encode("out.gvid", xyz_all, valid, quality=70)  # -> dict of figures
//
// Errors raise ValueError (bad arguments, options), FileNotFoundError, OSError or RuntimeError
// (damaged or unsupported streams) with the library's message, which names the file. The GIL is
// released while frames are decoded and encoded.
#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "gvkit/codec/encoder_options.hpp"
#include "gvkit/codec/encoder_tune.hpp"
#include "gvkit/codec/geometry_metrics.hpp"
#include "gvkit/codec/gvid_reader.hpp"
#include "gvkit/codec/gvid_writer.hpp"
#include "numpy_frames.hpp"

namespace py = pybind11;

namespace gvkit::python {
namespace {

template <typename T>
T value_or_raise(Result<T> result) {
  if (!result.is_ok()) raise_status(result.status());
  return std::move(result).value();
}

py::array strings(const std::vector<std::string>& values) {
  return py::module_::import("numpy").attr("array")(py::cast(values), "U");
}

// A .gvid stream opened for reading (the whole file is read on open).
class Reader {
 public:
  explicit Reader(const std::string& path) {
    Result<std::unique_ptr<codec::GvidReader>> r = [&] {
      py::gil_scoped_release release;
      return codec::GvidReader::open(path);
    }();
    reader_ = value_or_raise(std::move(r));
  }

  int64_t size() const { return reader_->frame_count(); }

  py::dict info() const {
    const codec::SequenceInfo& s = reader_->info();
    const codec::format::StreamFormat& f = reader_->format();
    py::dict d;
    d["path"] = reader_->name();
    d["width"] = s.width;
    d["height"] = s.height;
    d["frames"] = reader_->frame_count();
    d["fps"] = s.fps;
    d["bit_depth"] = s.bit_depth;
    d["has_texture"] = s.has_texture;
    d["format"] = std::to_string(f.major) + "." + std::to_string(f.minor);
    d["legacy"] = f.legacy();
    d["profile"] = f.legacy() ? py::object(py::none()) : py::str(codec::profile_name(f.profile));
    d["box_min_mm"] = py::make_tuple(s.box_min_mm[0], s.box_min_mm[1], s.box_min_mm[2]);
    d["box_max_mm"] = py::make_tuple(s.box_max_mm[0], s.box_max_mm[1], s.box_max_mm[2]);
    d["box_diagonal_mm"] = s.box_diagonal_mm();
    d["step_mm"] = s.step_mm();
    d["domain_pixels"] = s.domain_pixels();
    d["file_bytes"] = reader_->file_bytes();
    d["index_rebuilt"] = reader_->index_rebuilt();
    return d;
  }

  // Frame `index` (display order; negative counts from the end).
  py::tuple read(int64_t index, bool texture) {
    const GeometryImage image = decode(index);
    if (texture) return py::make_tuple(xyz_array(image), valid_array(image), texture_array(image));
    return py::make_tuple(xyz_array(image), valid_array(image));
  }

  py::tuple read_all() {
    const int64_t n = size();
    const int h = reader_->info().height, w = reader_->info().width;
    py::array_t<float> xyz({static_cast<py::ssize_t>(n), static_cast<py::ssize_t>(h),
                            static_cast<py::ssize_t>(w), py::ssize_t{3}});
    for (int64_t f = 0; f < n; ++f) {
      const GeometryImage image = decode(f);
      for (int y = 0; y < h; ++y)
        std::memcpy(xyz.mutable_data(f, y), image.xyz_mm.ptr<float>(y), sizeof(float) * 3 * w);
    }
    GeometryImage mask;
    mask.domain_mask = reader_->info().domain_mask;
    return py::make_tuple(xyz, valid_array(mask));
  }

  // Per frame, display order: packet bits and bytes, type ("I", "P", "B"), QP (8-bit units; 0
  // in lossless frames), position in the decode order, half resolution, reference frames.
  py::dict stats() const {
    const int64_t n = size();
    py::array_t<int64_t> bits(n), qp(n), position(n), refs(n);
    py::array_t<bool> half(n);
    std::vector<std::string> types;
    for (int64_t f = 0; f < n; ++f) {
      bits.mutable_at(f) = reader_->frame_bits(f);
      types.emplace_back(codec::format::frame_type_name(reader_->frame_type(f)));
      const auto header = reader_->packet_header(f);
      qp.mutable_at(f) = header.is_ok() ? header->qp : 0;
      half.mutable_at(f) = header.is_ok() && header->half_resolution;
      position.mutable_at(f) = reader_->decode_position(f);
      refs.mutable_at(f) = reader_->frame_references(f);
    }
    py::dict d;
    d["bits"] = bits;
    d["type"] = strings(types);
    d["qp"] = qp;
    d["decode_position"] = position;
    d["half_resolution"] = half;
    d["references"] = refs;
    const double vertices = static_cast<double>(std::max<int64_t>(1, info_pixels()));
    d["bits_per_vertex"] =
        py::array_t<double>(bits.attr("astype")("float64")) / py::float_(vertices);
    return d;
  }

 private:
  int64_t info_pixels() const { return reader_->info().domain_pixels(); }

  GeometryImage decode(int64_t index) {
    const int64_t n = size();
    if (index < 0) index += n;
    if (index < 0 || index >= n)
      throw py::index_error(reader_->name() + ": frame " + std::to_string(index) +
                            " out of range (" + std::to_string(n) + " frames)");
    Result<GeometryImage> image = [&] {
      py::gil_scoped_release release;
      return reader_->decode_frame(index);
    }();
    return value_or_raise(std::move(image));
  }

  std::unique_ptr<codec::GvidReader> reader_;
};

// A tune value as `gvkit encode --tune` takes it.
std::string tune_value(const py::handle& v) {
  if (py::isinstance<py::bool_>(v)) return v.cast<bool>() ? "on" : "off";
  if (py::isinstance<py::str>(v)) return v.cast<std::string>();
  if (py::isinstance<py::list>(v) || py::isinstance<py::tuple>(v)) {
    std::string out;
    for (const py::handle item : v) out += (out.empty() ? "" : ",") + tune_value(item);
    return out;
  }
  return py::str(v).cast<std::string>();
}

py::dict encode(const std::string& path, const py::array& xyz, const py::object& valid,
                const py::object& quality, const py::object& qp, const py::object& bitrate,
                const py::object& max_error_mm, bool lossless, const std::string& preset,
                const std::string& profile, double fps, int bit_depth, int gop, bool intra_only,
                int threads, const py::object& texture, const py::dict& tune) {
  const auto fail = [&](const Status& s) { raise_status(s.with_context(path)); };
  codec::EncoderOptions o;
  o.bit_depth = bit_depth;
  o.intra_period = gop;
  o.intra_only = intra_only;
  // 0: the hardware threads, at most 16 (as `gvkit encode`); the stream does not depend on it.
  o.threads = threads == 0
                  ? static_cast<int>(std::clamp(std::thread::hardware_concurrency(), 1u, 16u))
                  : threads;
  o.lossless = lossless;
  const int modes = !quality.is_none() + !bitrate.is_none() + !max_error_mm.is_none() + lossless;
  if (modes > 1)
    fail(invalid_argument("quality, bitrate, max_error_mm and lossless exclude each other"));
  if (!qp.is_none() && (lossless || !max_error_mm.is_none()))
    fail(invalid_argument("qp: lossless and max_error_mm coding have no QP"));
  if (!qp.is_none()) o.qp = qp.cast<int>();
  if (!quality.is_none()) o.target_psnr_db = quality.cast<double>();
  if (!bitrate.is_none()) o.bitrate_kbps = bitrate.cast<double>();
  if (!max_error_mm.is_none()) o.max_error_mm = max_error_mm.cast<double>();
  if (auto p = codec::parse_preset(preset); p.is_ok())
    o.preset = *p;
  else
    fail(p.status());
  if (auto p = codec::parse_profile(profile); p.is_ok())
    o.profile = *p;
  else
    fail(p.status());
  for (const auto& [key, value] : tune) {
    const Status s = codec::apply_tune(py::str(key).cast<std::string>(), tune_value(value), &o);
    if (!s.is_ok()) fail(s);
  }
  if (const Status s = o.check(); !s.is_ok()) fail(s);
  const std::vector<GeometryImage> frames = frames_from_arrays(xyz, valid, texture);
  auto made = codec::make_sequence_info(frames, o.bit_depth, fps);
  // Frames that do not make one video (sizes, masks, non-finite domain pixels): bad arguments.
  if (!made.is_ok()) fail(invalid_argument(made.status().message()));
  const codec::SequenceInfo info = std::move(made).value();

  std::vector<codec::GeometryError> errors;
  std::unique_ptr<codec::GvidWriter> writer;
  Status status;
  {
    py::gil_scoped_release release;
    status = [&]() -> Status {
      GVKIT_ASSIGN_OR_RETURN(writer, codec::GvidWriter::create(path, info, o));
      const auto report = [&](const std::vector<GeometryImage>& done) {
        for (const GeometryImage& recon : done)
          errors.push_back(codec::geometry_error(frames[errors.size()], recon));
      };
      for (const GeometryImage& frame : frames) {
        GVKIT_ASSIGN_OR_RETURN(const std::vector<GeometryImage> done, writer->write(frame));
        report(done);
      }
      GVKIT_ASSIGN_OR_RETURN(const std::vector<GeometryImage> rest, writer->finish());
      report(rest);
      return Status::ok();
    }();
  }
  // Named by the file (the writer's own messages already begin with it).
  if (!status.is_ok())
    raise_status(status.message().rfind(path, 0) == 0 ? status : status.with_context(path));

  const size_t n = frames.size();
  const double peak = info.box_diagonal_mm();
  const double vertices = static_cast<double>(info.domain_pixels());
  py::array_t<int64_t> bits(static_cast<py::ssize_t>(n)), qps(static_cast<py::ssize_t>(n));
  py::array_t<double> psnr(static_cast<py::ssize_t>(n)), rms(static_cast<py::ssize_t>(n)),
      max_mm(static_cast<py::ssize_t>(n));
  std::vector<std::string> types;
  codec::GeometryError total;
  int64_t frame_bytes = 0;
  for (size_t f = 0; f < n; ++f) {
    bits.mutable_at(f) = writer->frame_bytes()[f] * 8;
    frame_bytes += writer->frame_bytes()[f];
    qps.mutable_at(f) = writer->frame_qp()[f];
    types.emplace_back(codec::format::frame_type_name(writer->frame_types()[f]));
    psnr.mutable_at(f) = errors[f].psnr_db(peak);
    rms.mutable_at(f) = errors[f].rms_mm;
    max_mm.mutable_at(f) = errors[f].max_mm;
    codec::accumulate(total, errors[f]);
  }
  py::dict d;
  d["path"] = path;
  d["frames"] = n;
  d["width"] = info.width;
  d["height"] = info.height;
  d["format"] = std::to_string(codec::format::kMajorVersion) + "." +
                std::to_string(codec::format::kMinorVersion);
  d["profile"] = codec::profile_name(o.resolved_profile());
  d["file_bytes"] = writer->header_bytes() + frame_bytes;
  d["bits"] = bits;
  d["type"] = strings(types);
  d["qp"] = qps;
  d["psnr_db"] = psnr;
  d["rms_mm"] = rms;
  d["max_mm"] = max_mm;
  d["mean_psnr_db"] = total.psnr_db(peak);  // over all frames' pixels together
  d["mean_rms_mm"] = total.rms_mm;
  d["max_error_mm"] = total.max_mm;
  d["bits_per_vertex_per_frame"] = frame_bytes * 8.0 / vertices / static_cast<double>(n);
  d["kbit_per_s"] = frame_bytes * 8.0 / static_cast<double>(n) * fps / 1000.0;
  return d;
}

}  // namespace
}  // namespace gvkit::python

PYBIND11_MODULE(gvkit, m) {
  using gvkit::python::Reader;
  m.doc() =
      "gvkit: geometry videos (.gvid, format 2.0) as numpy arrays. open() reads a stream, "
      "encode() writes one.";
  py::class_<Reader>(m, "Reader",
                     "A .gvid stream opened for reading (gvkit.open). Frames are in display "
                     "order; r[i] is r.read(i); iterating yields (xyz, valid) per frame.")
      .def(py::init<const std::string&>(), py::arg("path"))
      .def_property_readonly("info", &Reader::info,
                             "dict: path, width, height, frames, fps, bit_depth, has_texture, "
                             "format ('2.0', or '1.x' with legacy True), profile ('lossless', "
                             "'intra', 'main'; None for legacy streams), box_min_mm, box_max_mm, "
                             "box_diagonal_mm, step_mm, domain_pixels, file_bytes, index_rebuilt")
      .def("__len__", &Reader::size)
      .def(
          "__getitem__", [](Reader& r, int64_t i) { return r.read(i, false); }, py::arg("index"))
      .def("read", &Reader::read, py::arg("index"), py::arg("texture") = false,
           "Frame `index` (display order, negative from the end) as (xyz, valid): xyz (H, W, 3) "
           "float32 mm, valid (H, W) bool, the domain mask (outside it xyz holds the codec's "
           "filler); with texture=True also the (H, W) float32 texture in [0, 1] or None. "
           "IndexError out of range, RuntimeError for a damaged frame (the message names the "
           "file and frame).")
      .def("read_all", &Reader::read_all,
           "Every frame: (xyz (N, H, W, 3) float32 mm, valid (H, W) bool).")
      .def("stats", &Reader::stats,
           "dict of numpy arrays per frame (display order): bits (packet size), bits_per_vertex, "
           "type ('I', 'P', 'B'), qp, decode_position, half_resolution, references.");
  m.def(
      "open", [](const std::string& path) { return Reader(path); }, py::arg("path"),
      "Opens a .gvid stream (format 2.0 or legacy 1.x): a Reader. FileNotFoundError when it is "
      "missing, RuntimeError when it is not a readable .gvid (the message says why).");
  m.def("encode", &gvkit::python::encode, py::arg("path"), py::arg("xyz"),
        py::arg("valid") = py::none(), py::kw_only(), py::arg("quality") = py::none(),
        py::arg("qp") = py::none(), py::arg("bitrate") = py::none(),
        py::arg("max_error_mm") = py::none(), py::arg("lossless") = false,
        py::arg("preset") = "slow", py::arg("profile") = "auto", py::arg("fps") = 30.0,
        py::arg("bit_depth") = 16, py::arg("gop") = 30, py::arg("intra_only") = false,
        py::arg("threads") = 0, py::arg("texture") = py::none(), py::arg("tune") = py::dict(),
        "Encodes frames into a .gvid stream (format 2.0), as `gvkit encode` does.\n"
        "xyz: (N, H, W, 3) or (H, W, 3) float mm; valid: (H, W) or (N, H, W) bool domain mask "
        "(the same in every frame), None = where xyz is finite. Rate: one of quality (geometry "
        "PSNR in dB), qp (constant QP; else -10), bitrate (kbit/s), max_error_mm (near-lossless) "
        "or lossless. threads: 1..16, 0 = the hardware threads (the stream does not depend on it). "
        "preset 'fast' or 'slow'; profile 'auto', 'lossless', 'intra' or 'main'; "
        "tune: {key: value} as `gvkit encode --tune key=value` (docs/encoding.md). Returns a "
        "dict: frames, format, profile, file_bytes, per-frame numpy arrays bits, type, qp, "
        "psnr_db, rms_mm, max_mm, and mean_psnr_db, mean_rms_mm, max_error_mm, "
        "bits_per_vertex_per_frame, kbit_per_s. ValueError for bad arguments or options, OSError "
        "when the file cannot be written.");
  py::list keys;
  for (const auto& k : gvkit::codec::tune_keys())
    keys.append(py::make_tuple(k.name, k.values, k.help));
  m.attr("tune_keys") = keys;
  m.attr("format_version") = "2.0";
}
