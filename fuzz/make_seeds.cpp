// Writes the binary seed inputs of the volume and DICOM targets: small valid files of every
// variant the readers handle (a few hundred bytes each), and headers of the real files in
// assets/cache (scripts/fetch-data.sh) shrunk to a few voxels. The text formats' seeds are the
// repository's own files, copied by scripts/fuzz.sh.
//
//   make_seeds <repository> <corpus folder>   writes <corpus folder>/<target>/<seed>
#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <zlib.h>

#include "engine/scene/io/volume_loader.h"

namespace {

namespace fs = std::filesystem;
using Bytes = std::vector<uint8_t>;

void save(const fs::path& path, const Bytes& bytes) {
  fs::create_directories(path.parent_path());
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
}

Bytes load(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return Bytes(std::istreambuf_iterator<char>(in), {});
}

Bytes text(const std::string& s) {
  return Bytes(s.begin(), s.end());
}

Bytes operator+(Bytes a, const Bytes& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

// A gzip member (windowBits 15 + 16) of the bytes.
Bytes gzip(const Bytes& data) {
  z_stream z{};
  deflateInit2(&z, Z_BEST_COMPRESSION, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY);
  Bytes out(deflateBound(&z, uLong(data.size())) + 32);
  z.next_in = const_cast<Bytef*>(data.data());
  z.avail_in = uInt(data.size());
  z.next_out = out.data();
  z.avail_out = uInt(out.size());
  deflate(&z, Z_FINISH);
  out.resize(z.total_out);
  deflateEnd(&z);
  return out;
}

// A ramp of n elements of `size` bytes, so the voxels are not all equal.
Bytes ramp(size_t n, size_t size) {
  Bytes data(n * size);
  for (size_t i = 0; i < data.size(); ++i) data[i] = uint8_t(i * 7 / size);
  return data;
}

template <class T>
void put(Bytes& b, size_t offset, T value, bool big_endian = false) {
  std::array<uint8_t, sizeof(T)> raw;
  std::memcpy(raw.data(), &value, sizeof(T));
  if (big_endian) std::reverse(raw.begin(), raw.end());
  std::memcpy(b.data() + offset, raw.data(), sizeof(T));
}

template <class T>
T get(const Bytes& b, size_t offset, bool big_endian) {
  std::array<uint8_t, sizeof(T)> raw;
  std::memcpy(raw.data(), b.data() + offset, sizeof(T));
  if (big_endian) std::reverse(raw.begin(), raw.end());
  T value;
  std::memcpy(&value, raw.data(), sizeof(T));
  return value;
}

// ---- NIfTI

// A NIfTI-1 header of dims (x, y, z, frames) with an sform (or a qform), then the voxels.
Bytes nifti1(std::array<int16_t, 4> dims, int16_t datatype, int16_t bitpix, bool big_endian,
             bool qform) {
  Bytes b(352, 0);
  put<int32_t>(b, 0, 348, big_endian);
  put<int16_t>(b, 40, int16_t(dims[3] > 1 ? 4 : dims[2] > 1 ? 3 : 2), big_endian);
  for (size_t i = 0; i < 4; ++i) put<int16_t>(b, 42 + 2 * i, dims[i], big_endian);
  put<int16_t>(b, 70, datatype, big_endian);
  put<int16_t>(b, 72, bitpix, big_endian);
  const float pixdim[4] = {-1.0f, 1.5f, 1.5f, 3.0f};
  for (size_t i = 0; i < 4; ++i) put<float>(b, 76 + 4 * i, pixdim[i], big_endian);
  put<float>(b, 108, 352.0f, big_endian);
  put<float>(b, 112, 2.0f, big_endian);  // scl_slope, scl_inter
  put<float>(b, 116, -10.0f, big_endian);
  put<int16_t>(b, qform ? 252 : 254, 1, big_endian);
  if (qform) {
    put<float>(b, 256, 0.0f, big_endian);
    put<float>(b, 260, 0.0f, big_endian);
    put<float>(b, 264, 0.7071f, big_endian);
  } else {
    const float srow[12] = {-1.5f, 0, 0, 90, 0, 1.5f, 0, -126, 0, 0, 3, -72};
    for (size_t i = 0; i < 12; ++i) put<float>(b, 280 + 4 * i, srow[i], big_endian);
  }
  std::memcpy(b.data() + 344, "n+1", 4);
  const size_t count = size_t(dims[0]) * dims[1] * dims[2] * std::max<int16_t>(dims[3], 1);
  return b + ramp(count, size_t(bitpix / 8));
}

Bytes nifti2(std::array<int64_t, 4> dims, int16_t datatype, int16_t bitpix) {
  Bytes b(544, 0);
  put<int32_t>(b, 0, 540);
  std::memcpy(b.data() + 4, "n+2\0\r\n\032\n", 8);
  put<int16_t>(b, 12, datatype);
  put<int16_t>(b, 14, bitpix);
  put<int64_t>(b, 16, dims[3] > 1 ? 4 : 3);
  for (size_t i = 0; i < 4; ++i) put<int64_t>(b, 24 + 8 * i, dims[i]);
  for (size_t i = 1; i < 4; ++i) put<double>(b, 104 + 8 * i, 0.8);
  put<int64_t>(b, 168, 544);
  put<double>(b, 176, 1.0);
  put<int32_t>(b, 348, 2);  // sform_code
  const double srow[12] = {0.8, 0, 0, -10, 0, 0.8, 0, -20, 0, 0, 0.8, 5};
  for (size_t i = 0; i < 12; ++i) put<double>(b, 400 + 8 * i, srow[i]);
  const size_t count = size_t(dims[0] * dims[1] * dims[2] * std::max<int64_t>(dims[3], 1));
  return b + ramp(count, size_t(bitpix / 8));
}

// A real NIfTI-1 file's header (and extensions) with its dims cut to 6x5x4 (and 2 frames where it
// had more), then that many voxels: the real file's orientation, types and byte order.
Bytes shrunk_nifti(const fs::path& file) {
  gzFile in = gzopen(file.c_str(), "rb");
  if (!in) return {};
  Bytes b(1 << 16);
  b.resize(size_t(std::max(0, gzread(in, b.data(), unsigned(b.size())))));
  gzclose(in);
  if (b.size() < 352) return {};
  const bool big = get<int32_t>(b, 0, false) != 348;
  if (get<int32_t>(b, 0, big) != 348) return {};
  const auto offset = size_t(get<float>(b, 108, big));
  const int16_t bitpix = get<int16_t>(b, 72, big);
  const int16_t rank = get<int16_t>(b, 40, big);
  if (offset < 348 || offset > b.size() || bitpix < 8) return {};
  const int16_t dims[4] = {6, 5, 4, 2};
  size_t count = 1;
  for (int16_t axis = 0; axis < std::min<int16_t>(rank, 4); ++axis) {
    put<int16_t>(b, 42 + 2 * size_t(axis), dims[axis], big);
    count *= size_t(dims[axis]);
  }
  b.resize(offset);
  return b + ramp(count, size_t(bitpix / 8));
}

void nifti_seeds(const fs::path& repo, const fs::path& out) {
  const fs::path dir = out / "fuzz_nifti";
  save(dir / "int16_sform.nii", nifti1({8, 8, 4, 1}, 4, 16, false, false));
  save(dir / "uint8_qform_big_endian.nii", nifti1({6, 5, 3, 1}, 2, 8, true, true));
  save(dir / "float64_4d.nii", nifti1({4, 4, 2, 3}, 64, 64, false, false));
  save(dir / "int8_2d.nii", nifti1({8, 8, 1, 1}, 256, 8, false, true));
  save(dir / "uint16_gzip.nii", gzip(nifti1({8, 8, 4, 1}, 512, 16, false, false)));
  save(dir / "nifti2_float32.nii", nifti2({4, 4, 3, 1}, 16, 32));
  save(dir / "nifti2_int32_4d.nii", nifti2({3, 3, 2, 2}, 8, 32));
  for (const char* real :
       {"mricron/ch2.nii.gz", "mricron/aal.nii.gz", "nibabel/example4d.nii.gz"}) {
    const Bytes b = shrunk_nifti(repo / "assets/cache" / real);
    if (b.empty()) continue;
    const std::string name = fs::path(real).filename().string();
    save(dir / ("real_" + name.substr(0, name.find('.')) + ".nii"), b);
    save(dir / ("real_" + name.substr(0, name.find('.')) + "_gzip.nii"), gzip(b));
  }
}

// ---- NIfTI header extensions

// An extension of `code` whose data is padded with NULs to a multiple of 16 with its 8 bytes.
Bytes extension(int32_t code, const std::string& data, bool big_endian) {
  Bytes e(8, 0);
  e = e + text(data);
  e.resize((e.size() + 15) / 16 * 16, 0);
  put<int32_t>(e, 0, int32_t(e.size()), big_endian);
  put<int32_t>(e, 4, code, big_endian);
  return e;
}

// A NIfTI header (NIfTI-1 or -2 as `header` is) with the extender set, the chain, vox_offset after
// it and the voxels.
Bytes with_extensions(Bytes header, size_t header_bytes, const Bytes& chain, bool big_endian) {
  Bytes voxels(header.begin() + std::ptrdiff_t(header_bytes + 4), header.end());
  header.resize(header_bytes + 4);
  header[header_bytes] = 1;
  const size_t offset = header_bytes + 4 + chain.size();
  if (header_bytes == 348)
    put<float>(header, 108, float(offset), big_endian);
  else
    put<int64_t>(header, 168, int64_t(offset));
  return header + chain + voxels;
}

void nifti_extension_seeds(const fs::path& out) {
  const fs::path dir = out / "fuzz_nifti_extensions";
  const std::string table =
      "<?xml version=\"1.0\" encoding=\"UTF-8\"?> <CaretExtension> <VolumeInformation Index=\"0\">"
      " <LabelTable>\n<Label Key=\"1\" Red=\"1.0\" Green=\"0.0\" Blue=\"0.0\" Alpha=\"1\">"
      "<![CDATA[spleen]]></Label>\n<Label Key=\"2\" Red=\"0.0\" Green=\"1.0\" Blue=\"0.0\" "
      "Alpha=\"1\"><![CDATA[kidney_right]]></Label>\n </LabelTable> <VolumeType><![CDATA[Label]]>"
      "</VolumeType> </VolumeInformation></CaretExtension>\n";
  for (const bool big : {false, true}) {
    const Bytes chain = extension(6, "a comment", big) + extension(0, table, big);
    const Bytes b = with_extensions(nifti1({4, 4, 2, 1}, 2, 8, big, false), 348, chain, big);
    save(dir / (big ? "table_big_endian.nii" : "table.nii"), b);
    if (!big) save(dir / "table_gzip.nii", gzip(b));
  }
  save(dir / "table_nifti2.nii",
       with_extensions(nifti2({3, 3, 2, 1}, 2, 8), 540, extension(0, table, false), false));
  save(dir / "comment_only.nii", with_extensions(nifti1({4, 4, 2, 1}, 2, 8, false, false), 348,
                                                 extension(6, "no table", false), false));
}

// ---- FreeSurfer MGH

// A big-endian MGH header (dims, frames, type, goodRASflag and an oblique geometry), then the
// voxels and the scan parameters FreeSurfer writes after them.
Bytes mgh(std::array<int32_t, 4> dims, int32_t type, size_t element_size, int16_t good_ras) {
  Bytes b(284, 0);
  put<int32_t>(b, 0, 1, true);
  for (size_t i = 0; i < 4; ++i) put<int32_t>(b, 4 + 4 * i, dims[i], true);
  put<int32_t>(b, 20, type, true);
  put<int16_t>(b, 28, good_ras, true);
  const float fields[15] = {1.0f, 1.5f, 2.0f,  0.0f, 0.8f,  0.6f,   -1.0f, 0.0f,
                            0.0f, 0.0f, -0.6f, 0.8f, 10.0f, -20.0f, 30.0f};
  for (size_t i = 0; i < 15; ++i) put<float>(b, 30 + 4 * i, fields[i], true);
  const size_t count = size_t(dims[0]) * size_t(dims[1]) * size_t(dims[2]) * size_t(dims[3]);
  return b + ramp(count, element_size) + Bytes(20, 0);
}

void mgh_seeds(const fs::path& repo, const fs::path& out) {
  const fs::path dir = out / "fuzz_mgh";
  save(dir / "uchar.mgh", mgh({6, 5, 4, 1}, 0, 1, 1));
  save(dir / "short_gzip.mgz", gzip(mgh({6, 5, 4, 1}, 4, 2, 1)));
  save(dir / "int_4d.mgh", mgh({4, 3, 2, 3}, 1, 4, 1));
  save(dir / "float_no_ras.mgz", gzip(mgh({4, 4, 4, 1}, 3, 4, 0)));
  const Bytes real = load(repo / "assets/cache/nibabel/test.mgz");
  if (!real.empty()) save(dir / "real_nibabel_test.mgz", real);
}

// ---- MetaImage

strata::Volume small_volume(strata::VoxelType type, glm::uvec3 dims) {
  strata::Volume v;
  v.type = type;
  v.dims = dims;
  v.spacing = {0.5f, 0.75f, 2.0f};
  v.origin = {-10.0f, 4.5f, 30.0f};
  v.direction = glm::mat3(0, 1, 0, -1, 0, 0, 0, 0, 1);
  v.voxels.resize(v.voxel_count() * strata::voxel_size(type));
  for (size_t i = 0; i < v.voxels.size(); ++i) v.voxels[i] = std::byte(i * 13);
  return v;
}

void metaimage_seeds(const fs::path& out) {
  using strata::VoxelType;
  const fs::path dir = out / "fuzz_metaimage";
  fs::create_directories(dir);
  strata::write_metaimage(dir / "uint8.mha", small_volume(VoxelType::uint8, {8, 8, 4}));
  strata::write_metaimage(dir / "int16_zlib.mha", small_volume(VoxelType::int16, {8, 6, 4}), true);
  strata::write_metaimage(dir / "float32.mha", small_volume(VoxelType::float32, {4, 4, 3}));
  strata::write_metaimage(dir / "uint16_zlib.mha", small_volume(VoxelType::uint16, {5, 5, 5}),
                          true);
  const std::string header4d =
      "ObjectType = Image\nNDims = 4\nBinaryData = True\nBinaryDataByteOrderMSB = True\n"
      "TransformMatrix = 1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1\nOffset = 0 0 0 0\n"
      "ElementSpacing = 1 1 2.5 1\nDimSize = 4 3 2 3\nElementType = MET_USHORT\n"
      "ElementDataFile = LOCAL\n";
  save(dir / "uint16_4d_msb.mha", text(header4d) + ramp(4 * 3 * 2 * 3, 2));
  const std::string header2d =
      "NDims = 2\nElementSize = 0.5 0.5\nPosition = 3 4\nOrientation = 0 1 1 0\n"
      "DimSize = 8 8\nElementType = MET_SHORT\nElementDataFile = LOCAL\n";
  save(dir / "int16_2d.mha", text(header2d) + ramp(64, 2));
  // A data file named by the header: the target's own input, its voxels at the end (HeaderSize -1).
  const std::string detached =
      "ObjectType = Image\nNDims = 3\nDimSize = 4 4 2\nElementType = MET_UCHAR\n"
      "HeaderSize = -1\nElementDataFile = input.mha\n";
  save(dir / "detached_self.mha", text(detached) + ramp(32, 1));
}

// ---- NRRD

void nrrd_seeds(const fs::path& out) {
  const fs::path dir = out / "fuzz_nrrd";
  save(dir / "short_lps_raw.nrrd",
       text("NRRD0004\n# Complete NRRD file format specification at:\n"
            "type: short\ndimension: 3\nspace: left-posterior-superior\nsizes: 6 5 4\n"
            "space directions: (0.9,0,0) (0,0.9,0) (0,0,2.5)\nkinds: domain domain domain\n"
            "endian: little\nencoding: raw\nspace origin: (-10,20,-30.5)\n\n") +
           ramp(6 * 5 * 4, 2));
  save(dir / "float_ras_gzip.nrrd",
       text("NRRD0005\ntype: float\ndimension: 3\nspace: RAS\nsizes: 4 4 3\n"
            "space directions: (0,1,0) (-1,0,0) (0,0,1)\nendian: big\nencoding: gzip\n"
            "space origin: (1,2,3)\n\n") +
           gzip(ramp(4 * 4 * 3, 4)));
  save(dir / "uchar_spacings.nrrd",
       text("NRRD0001\ntype: uchar\ndimension: 3\nsizes: 8 8 2\nspacings: 1 1 3\n"
            "encoding: raw\nline skip: 1\nbyte skip: 2\n\nskipped line\nxx") +
           ramp(128, 1));
  save(dir / "ushort_4d.nrrd",
       text("NRRD0004\ntype: unsigned short\ndimension: 4\nspace: scanner-xyz\n"
            "sizes: 3 3 2 4\nspace directions: (1,0,0) (0,1,0) (0,0,1) none\n"
            "kinds: space space space list\nendian: little\nencoding: raw\n\n") +
           ramp(3 * 3 * 2 * 4, 2));
  save(dir / "uint8_2d.nrrd",
       text("NRRD0004\ntype: uint8\ndimension: 2\nspace: LAS\nsizes: 8 6\n"
            "space directions: (0.5,0,0) (0,0.5,0)\nencoding: raw\nkey:=value\n\n") +
           ramp(48, 1));
  save(dir / "byte_skip_end.nrrd",
       text("NRRD0004\ntype: short\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n"
            "byte skip: -1\n\nheader junk") +
           ramp(8, 2));
  save(dir / "detached_self.nrrd",
       text("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 4 4 2\nencoding: raw\n"
            "data file: input.nrrd\nbyte skip: -1\n") +
           ramp(32, 1));
}

// ---- DICOM

// A real DICOM file with its pixel data cut to at most 64 bytes (length rewritten), so the seed
// is a few KB and still walks cleanly to its end. Finds the last (7fe0,0010) tag.
Bytes shrunk_dicom(const Bytes& file) {
  for (size_t at = file.size() >= 12 ? file.size() - 12 : 0; at > 132; --at) {
    if (!(file[at] == 0xe0 && file[at + 1] == 0x7f && file[at + 2] == 0x10 && file[at + 3] == 0))
      continue;
    Bytes b(file.begin(), file.begin() + ptrdiff_t(at));
    const bool explicit_vr = (file[at + 4] == 'O' && (file[at + 5] == 'W' || file[at + 5] == 'B'));
    const size_t header = explicit_vr ? 12 : 8;
    Bytes head(file.begin() + ptrdiff_t(at), file.begin() + ptrdiff_t(at + header));
    const uint32_t length = get<uint32_t>(head, header - 4, false);
    const uint32_t kept = length == 0xffffffff ? length : std::min<uint32_t>(length, 64);
    if (kept == 0xffffffff) return {};  // encapsulated: left as it is
    put<uint32_t>(head, header - 4, kept);
    return b + head + ramp(kept, 1);
  }
  return {};
}

void dicom_seeds(const fs::path& repo, const fs::path& out) {
  const fs::path dir = out / "fuzz_dicom_structure";
  for (const char* name : {"CT_small.dcm", "MR_small.dcm", "MR_small_implicit.dcm"}) {
    const Bytes b = shrunk_dicom(load(repo / "assets/cache/dicom" / name));
    if (b.empty()) continue;
    save(dir / name, b);
    // The same data set without preamble and meta group: a bare data set.
    size_t pos = 132;
    while (pos + 8 <= b.size() && b[pos] == 2 && b[pos + 1] == 0)
      pos += 8 + get<uint16_t>(b, pos + 6, false);  // meta elements: explicit VR, short lengths
    if (pos < b.size())
      save(dir / ("bare_" + std::string(name)), Bytes(b.begin() + ptrdiff_t(pos), b.end()));
  }
  const fs::path series = repo / "assets/cache/dicom/CT5N";
  std::error_code error;
  for (const auto& entry : fs::directory_iterator(series, error)) {
    const Bytes b = shrunk_dicom(load(entry.path()));
    if (!b.empty()) save(dir / ("CT5N_" + entry.path().filename().string() + ".dcm"), b);
    break;  // one slice of the series is enough
  }
  // A small hand-written Part 10 file: explicit VR little endian, a sequence of undefined length.
  Bytes b(128, 0);
  b = b + text("DICM");
  const auto element = [&](uint16_t g, uint16_t e, const char* vr, const Bytes& value) {
    Bytes h(8, 0);
    put<uint16_t>(h, 0, g);
    put<uint16_t>(h, 2, e);
    h[4] = uint8_t(vr[0]);
    h[5] = uint8_t(vr[1]);
    put<uint16_t>(h, 6, uint16_t(value.size()));
    b = b + h + value;
  };
  element(0x0002, 0x0010, "UI", text("1.2.840.10008.1.2.1"));
  element(0x0008, 0x0060, "CS", text("CT"));
  Bytes seq(12, 0);
  put<uint16_t>(seq, 0, 0x0008);
  put<uint16_t>(seq, 2, 0x1140);
  seq[4] = 'S';
  seq[5] = 'Q';
  put<uint32_t>(seq, 8, 0xffffffff);
  Bytes item(8, 0);
  put<uint16_t>(item, 0, 0xfffe);
  put<uint16_t>(item, 2, 0xe000);
  put<uint32_t>(item, 4, 0xffffffff);
  Bytes item_end(8, 0), seq_end(8, 0);
  put<uint16_t>(item_end, 0, 0xfffe);
  put<uint16_t>(item_end, 2, 0xe00d);
  put<uint16_t>(seq_end, 0, 0xfffe);
  put<uint16_t>(seq_end, 2, 0xe0dd);
  b = b + seq + item;
  element(0x0008, 0x1150, "UI", text("1.2.3"));
  b = b + item_end + seq_end;
  element(0x0028, 0x0010, "US", Bytes{4, 0});
  save(dir / "sequence_undefined_length.dcm", b);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: make_seeds <repository> <corpus folder>\n");
    return 2;
  }
  const fs::path repo = argv[1], out = argv[2];
  nifti_seeds(repo, out);
  nifti_extension_seeds(out);
  mgh_seeds(repo, out);
  metaimage_seeds(out);
  nrrd_seeds(out);
  dicom_seeds(repo, out);
  return 0;
}
