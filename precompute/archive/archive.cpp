#include "precompute/archive/archive.h"

#include <algorithm>
#include <numeric>
#include <type_traits>
#include <utility>

#include "precompute/archive/hdf5_handle.h"

namespace quiver {

using hdf5::Handle;
using hdf5::Where;

namespace {

static_assert(std::is_same_v<hid_t, int64_t>, "Archive stores the file's hid_t as int64_t");

// How each element type is stored (little-endian, whatever the machine) and read into memory.
template <class T>
struct Stored;
template <>
struct Stored<double> {
  static hid_t file() { return H5T_IEEE_F64LE; }
  static hid_t memory() { return H5T_NATIVE_DOUBLE; }
  static constexpr H5T_class_t typeClass = H5T_FLOAT;
  static constexpr const char* typeName = "floating-point";
};
template <>
struct Stored<int64_t> {
  static hid_t file() { return H5T_STD_I64LE; }
  static hid_t memory() { return H5T_NATIVE_INT64; }
  static constexpr H5T_class_t typeClass = H5T_INTEGER;
  static constexpr const char* typeName = "integer";
};
template <>
struct Stored<int32_t> {
  static hid_t file() { return H5T_STD_I32LE; }
  static hid_t memory() { return H5T_NATIVE_INT32; }
  static constexpr H5T_class_t typeClass = H5T_INTEGER;
  static constexpr const char* typeName = "integer";
};

// Variable-length UTF-8 strings: h5py reads them as str and h5dump prints them plainly, and their
// bytes live in the global heap, so long values (command lines) never hit the 64 KiB attribute limit.
Handle utf8StringType(const Where& w) {
  Handle type = w.own(H5Tcopy(H5T_C_S1), H5Tclose, "cannot make a string type");
  w.check(H5Tset_size(type.get(), H5T_VARIABLE), "cannot make a string type");
  w.check(H5Tset_cset(type.get(), H5T_CSET_UTF8), "cannot make a string type");
  return type;
}

Handle collectiveTransfer(const Where& w) {
  Handle dxpl = w.own(H5Pcreate(H5P_DATASET_XFER), H5Pclose, "cannot create a transfer property list");
  w.check(H5Pset_dxpl_mpio(dxpl.get(), H5FD_MPIO_COLLECTIVE), "cannot request collective transfer");
  return dxpl;
}

// True when every link along `path` exists ("/" always does).
bool pathExists(hid_t file, const std::string& path, const Where& w) {
  for (size_t end = path.find('/', 1);; end = path.find('/', end + 1)) {
    std::string prefix = path.substr(0, end);
    if (prefix.find_first_not_of('/') != std::string::npos &&
        w.check(H5Lexists(file, prefix.c_str(), H5P_DEFAULT), "cannot look up " + prefix) == 0)
      return false;
    if (end == std::string::npos) return true;
  }
}

H5I_type_t objectType(hid_t file, const std::string& path, const Where& w) {
  Handle object = w.own(H5Oopen(file, path.c_str(), H5P_DEFAULT), H5Oclose, "cannot open the object");
  return H5Iget_type(object.get());
}

Handle intermediateGroups(const Where& w) {
  Handle lcpl = w.own(H5Pcreate(H5P_LINK_CREATE), H5Pclose, "cannot create a link property list");
  w.check(H5Pset_create_intermediate_group(lcpl.get(), 1), "cannot request intermediate groups");
  return lcpl;
}

std::vector<hsize_t> toDims(const std::vector<int64_t>& shape, const Where& w) {
  for (int64_t d : shape)
    if (d < 0) w.fail("negative dimension " + std::to_string(d));
  return {shape.begin(), shape.end()};
}

Handle makeSpace(const std::vector<int64_t>& shape, const Where& w) {
  if (shape.empty()) return w.own(H5Screate(H5S_SCALAR), H5Sclose, "cannot create a scalar dataspace");
  std::vector<hsize_t> dims = toDims(shape, w);
  return w.own(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr), H5Sclose,
               "cannot create a dataspace");
}

std::vector<int64_t> spaceShape(hid_t space, const Where& w) {
  int rank = w.check(H5Sget_simple_extent_ndims(space), "cannot read the dataspace");
  std::vector<hsize_t> dims(static_cast<size_t>(rank));
  w.check(H5Sget_simple_extent_dims(space, dims.data(), nullptr), "cannot read the dataspace");
  return {dims.begin(), dims.end()};
}

int64_t elementCount(const std::vector<int64_t>& shape) {
  return std::accumulate(shape.begin(), shape.end(), int64_t(1), std::multiplies<>());
}

// Creates the dataset at `path`, replacing a dataset already there (its shape may differ).
Handle createDataset(hid_t file, const std::string& path, hid_t fileType, const std::vector<int64_t>& shape,
                     const Where& w) {
  if (pathExists(file, path, w)) {
    if (objectType(file, path, w) != H5I_DATASET) w.fail("exists and is not a dataset");
    w.check(H5Ldelete(file, path.c_str(), H5P_DEFAULT), "cannot remove the old dataset");
  }
  Handle space = makeSpace(shape, w);
  // Every element is written right after creation, so skip writing fill values first.
  Handle dcpl = w.own(H5Pcreate(H5P_DATASET_CREATE), H5Pclose, "cannot create a dataset property list");
  w.check(H5Pset_fill_time(dcpl.get(), H5D_FILL_TIME_NEVER), "cannot set the fill time");
  Handle lcpl = intermediateGroups(w);
  return w.own(H5Dcreate2(file, path.c_str(), fileType, space.get(), lcpl.get(), dcpl.get(), H5P_DEFAULT),
               H5Dclose, "cannot create the dataset");
}

// Readers convert within a class (int32 to int64, float32 to double), never across classes.
void requireClass(hid_t type, H5T_class_t wanted, const char* wantedName, const Where& w) {
  if (w.check(H5Tget_class(type), "cannot read the datatype") != wanted)
    w.fail(std::string("is not of ") + wantedName + " type");
}

Handle openDataset(hid_t file, H5T_class_t wanted, const char* wantedName, const Where& w) {
  if (!pathExists(file, w.object, w)) w.fail("no such dataset");
  Handle dataset = w.own(H5Dopen2(file, w.object.c_str(), H5P_DEFAULT), H5Dclose, "cannot open the dataset");
  Handle type = w.own(H5Dget_type(dataset.get()), H5Tclose, "cannot read the datatype");
  requireClass(type.get(), wanted, wantedName, w);
  return dataset;
}

template <class T>
void writeWhole(hid_t file, int rank, const std::vector<int64_t>& shape, const T* data, const Where& w) {
  Handle dataset = createDataset(file, w.object, Stored<T>::file(), shape, w);
  if (elementCount(shape) == 0) return;  // no storage to write to (all ranks agree)
  Handle space = w.own(H5Dget_space(dataset.get()), H5Sclose, "cannot read the dataspace");
  if (rank != 0) w.check(H5Sselect_none(space.get()), "cannot select nothing");
  const T placeholder{};  // HDF5 refuses a null buffer even when nothing is selected
  Handle dxpl = collectiveTransfer(w);
  w.check(H5Dwrite(dataset.get(), Stored<T>::memory(), space.get(), space.get(), dxpl.get(),
                   rank == 0 ? data : &placeholder),
          "cannot write the dataset");
}

template <class T>
std::vector<T> readWhole(hid_t file, std::vector<int64_t>& shape, const Where& w) {
  Handle dataset = openDataset(file, Stored<T>::typeClass, Stored<T>::typeName, w);
  Handle space = w.own(H5Dget_space(dataset.get()), H5Sclose, "cannot read the dataspace");
  shape = spaceShape(space.get(), w);
  std::vector<T> values(static_cast<size_t>(elementCount(shape)));
  if (values.empty()) return values;
  Handle dxpl = collectiveTransfer(w);
  w.check(H5Dread(dataset.get(), Stored<T>::memory(), H5S_ALL, H5S_ALL, dxpl.get(), values.data()),
          "cannot read the dataset");
  return values;
}

// Every rank learns every rank's [start, start + count) and checks them the same way, so a bad
// slab on one rank makes all ranks throw the same error instead of leaving the others waiting.
void agreeOnSlabs(MPI_Comm comm, const std::vector<int64_t>& shape, int axis, int64_t start, int64_t count,
                  bool mustTile, const Where& w) {
  if (axis < 0 || axis >= static_cast<int>(shape.size()))
    w.fail("slab axis " + std::to_string(axis) + " is outside a dataset of rank " + std::to_string(shape.size()));
  int size = 1;
  MPI_Comm_size(comm, &size);
  std::vector<int64_t> all(2 * static_cast<size_t>(size));
  const int64_t mine[2] = {start, count};
  MPI_Allgather(mine, 2, MPI_INT64_T, all.data(), 2, MPI_INT64_T, comm);
  const int64_t extent = shape[static_cast<size_t>(axis)];
  std::vector<std::pair<int64_t, int64_t>> slabs;
  for (int r = 0; r < size; ++r) {
    int64_t s = all[2 * r], c = all[2 * r + 1];
    if (s < 0 || c < 0 || s > extent - c)
      w.fail("rank " + std::to_string(r) + "'s slab [" + std::to_string(s) + ", " + std::to_string(s + c) +
             ") is outside axis " + std::to_string(axis) + " of length " + std::to_string(extent));
    if (c > 0) slabs.emplace_back(s, c);
  }
  if (!mustTile) return;
  std::sort(slabs.begin(), slabs.end());
  int64_t covered = 0;
  for (const auto& [s, c] : slabs) {
    if (s != covered) break;
    covered += c;
  }
  if (covered != extent)
    w.fail("the ranks' slabs do not tile axis " + std::to_string(axis) + " of length " + std::to_string(extent) +
           " (gaps or overlaps)");
}

// The memory and file dataspaces of one rank's slab of `dataset` (nothing selected when count is 0).
struct SlabSpaces {
  Handle memory, file;
};
SlabSpaces selectSlab(hid_t dataset, int axis, int64_t start, int64_t count, const Where& w) {
  Handle file = w.own(H5Dget_space(dataset), H5Sclose, "cannot read the dataspace");
  std::vector<int64_t> slabShape = spaceShape(file.get(), w);
  slabShape[static_cast<size_t>(axis)] = count;
  Handle memory = makeSpace(slabShape, w);
  if (count == 0) {
    w.check(H5Sselect_none(file.get()), "cannot select nothing");
    w.check(H5Sselect_none(memory.get()), "cannot select nothing");
  } else {
    std::vector<hsize_t> offset(slabShape.size(), 0), extent = toDims(slabShape, w);
    offset[static_cast<size_t>(axis)] = static_cast<hsize_t>(start);
    w.check(H5Sselect_hyperslab(file.get(), H5S_SELECT_SET, offset.data(), nullptr, extent.data(), nullptr),
            "cannot select the slab");
  }
  return {std::move(memory), std::move(file)};
}

bool attributeExists(hid_t file, const std::string& objectPath, const std::string& name, const Where& w) {
  return w.check(H5Aexists_by_name(file, objectPath.c_str(), name.c_str(), H5P_DEFAULT),
                 "cannot look up the attribute") > 0;
}

void writeAttribute(hid_t file, const std::string& objectPath, const std::string& name, hid_t type,
                    const void* value, const Where& w) {
  if (attributeExists(file, objectPath, name, w))
    w.check(H5Adelete_by_name(file, objectPath.c_str(), name.c_str(), H5P_DEFAULT), "cannot remove the old attribute");
  Handle space = w.own(H5Screate(H5S_SCALAR), H5Sclose, "cannot create a scalar dataspace");
  Handle attribute = w.own(H5Acreate_by_name(file, objectPath.c_str(), name.c_str(), type, space.get(), H5P_DEFAULT,
                                             H5P_DEFAULT, H5P_DEFAULT),
                           H5Aclose, "cannot create the attribute");
  w.check(H5Awrite(attribute.get(), type, value), "cannot write the attribute");
}

Handle openScalarAttribute(hid_t file, const std::string& objectPath, const std::string& name, const Where& w) {
  if (!pathExists(file, objectPath, w)) w.fail("no such object");
  if (!attributeExists(file, objectPath, name, w)) w.fail("no such attribute");
  Handle attribute = w.own(H5Aopen_by_name(file, objectPath.c_str(), name.c_str(), H5P_DEFAULT, H5P_DEFAULT),
                           H5Aclose, "cannot open the attribute");
  Handle space = w.own(H5Aget_space(attribute.get()), H5Sclose, "cannot read the attribute's dataspace");
  if (H5Sget_simple_extent_npoints(space.get()) != 1) w.fail("the attribute holds more than one value");
  return attribute;
}

template <class T>
T readNumericAttribute(hid_t file, const std::string& objectPath, const std::string& name, const Where& w) {
  Handle attribute = openScalarAttribute(file, objectPath, name, w);
  Handle type = w.own(H5Aget_type(attribute.get()), H5Tclose, "cannot read the attribute's datatype");
  requireClass(type.get(), Stored<T>::typeClass, Stored<T>::typeName, w);
  T value{};
  w.check(H5Aread(attribute.get(), Stored<T>::memory(), &value), "cannot read the attribute");
  return value;
}

Where attributeWhere(const std::string& file, const std::string& objectPath, const std::string& name) {
  return {file, objectPath + " (attribute " + name + ")"};
}

} // namespace

Archive::Archive(MPI_Comm comm, const std::string& path, Mode mode) : comm_(comm), path_(path) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  MPI_Comm_rank(comm_, &rank_);
  Where w{path_, "/"};
  Handle fapl = w.own(H5Pcreate(H5P_FILE_ACCESS), H5Pclose, "cannot create a file access property list");
  w.check(H5Pset_fapl_mpio(fapl.get(), comm_, MPI_INFO_NULL), "cannot set up MPI-IO access");
  if (mode == Mode::Create)
    file_ = w.check(H5Fcreate(path_.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl.get()), "cannot create the file");
  else
    file_ = w.check(H5Fopen(path_.c_str(), mode == Mode::ReadWrite ? H5F_ACC_RDWR : H5F_ACC_RDONLY, fapl.get()),
                    "cannot open the file as HDF5");
}

Archive::~Archive() {
  if (file_ >= 0) H5Fclose(file_);
}

bool Archive::exists(const std::string& objectPath) const { return pathExists(file_, objectPath, {path_, objectPath}); }

void Archive::createGroup(const std::string& groupPath) {
  Where w{path_, groupPath};
  if (pathExists(file_, groupPath, w)) {
    if (objectType(file_, groupPath, w) != H5I_GROUP) w.fail("exists and is not a group");
    return;
  }
  Handle lcpl = intermediateGroups(w);
  w.own(H5Gcreate2(file_, groupPath.c_str(), lcpl.get(), H5P_DEFAULT, H5P_DEFAULT), H5Gclose,
        "cannot create the group");
}

void Archive::removeObject(const std::string& objectPath) {
  Where w{path_, objectPath};
  if (!pathExists(file_, objectPath, w)) w.fail("no such object");
  w.check(H5Ldelete(file_, objectPath.c_str(), H5P_DEFAULT), "cannot remove the object");
}

void Archive::writeReplicated(const std::string& datasetPath, const std::vector<int64_t>& shape, const double* data) {
  writeWhole(file_, rank_, shape, data, {path_, datasetPath});
}
void Archive::writeReplicated(const std::string& datasetPath, const std::vector<int64_t>& shape, const int64_t* data) {
  writeWhole(file_, rank_, shape, data, {path_, datasetPath});
}
void Archive::writeReplicated(const std::string& datasetPath, const std::vector<int64_t>& shape, const int32_t* data) {
  writeWhole(file_, rank_, shape, data, {path_, datasetPath});
}

std::vector<double> Archive::readReplicatedDouble(const std::string& datasetPath, std::vector<int64_t>& shape) const {
  return readWhole<double>(file_, shape, {path_, datasetPath});
}
std::vector<int64_t> Archive::readReplicatedInt(const std::string& datasetPath, std::vector<int64_t>& shape) const {
  return readWhole<int64_t>(file_, shape, {path_, datasetPath});
}

void Archive::writeSlab(const std::string& datasetPath, const std::vector<int64_t>& shape, int axis, int64_t start,
                        int64_t count, const double* data) {
  Where w{path_, datasetPath};
  agreeOnSlabs(comm_, shape, axis, start, count, true, w);
  Handle dataset = createDataset(file_, datasetPath, Stored<double>::file(), shape, w);
  if (elementCount(shape) == 0) return;
  SlabSpaces spaces = selectSlab(dataset.get(), axis, start, count, w);
  const double placeholder = 0;
  Handle dxpl = collectiveTransfer(w);
  w.check(H5Dwrite(dataset.get(), H5T_NATIVE_DOUBLE, spaces.memory.get(), spaces.file.get(), dxpl.get(),
                   count > 0 ? data : &placeholder),
          "cannot write the slab");
}

std::vector<double> Archive::readSlab(const std::string& datasetPath, int axis, int64_t start, int64_t count,
                                      std::vector<int64_t>& shape) const {
  Where w{path_, datasetPath};
  Handle dataset = openDataset(file_, Stored<double>::typeClass, Stored<double>::typeName, w);
  Handle space = w.own(H5Dget_space(dataset.get()), H5Sclose, "cannot read the dataspace");
  shape = spaceShape(space.get(), w);
  agreeOnSlabs(comm_, shape, axis, start, count, false, w);
  if (elementCount(shape) == 0) return {};
  SlabSpaces spaces = selectSlab(dataset.get(), axis, start, count, w);
  std::vector<int64_t> slabShape = shape;
  slabShape[static_cast<size_t>(axis)] = count;
  std::vector<double> values(static_cast<size_t>(elementCount(slabShape)));
  double placeholder = 0;
  Handle dxpl = collectiveTransfer(w);
  w.check(H5Dread(dataset.get(), H5T_NATIVE_DOUBLE, spaces.memory.get(), spaces.file.get(), dxpl.get(),
                  values.empty() ? &placeholder : values.data()),
          "cannot read the slab");
  return values;
}

void Archive::setAttribute(const std::string& objectPath, const std::string& name, const std::string& value) {
  Where w = attributeWhere(path_, objectPath, name);
  Handle type = utf8StringType(w);
  const char* text = value.c_str();
  writeAttribute(file_, objectPath, name, type.get(), &text, w);
}
void Archive::setAttribute(const std::string& objectPath, const std::string& name, double value) {
  writeAttribute(file_, objectPath, name, Stored<double>::file(), &value, attributeWhere(path_, objectPath, name));
}
void Archive::setAttribute(const std::string& objectPath, const std::string& name, int64_t value) {
  writeAttribute(file_, objectPath, name, Stored<int64_t>::file(), &value, attributeWhere(path_, objectPath, name));
}

bool Archive::hasAttribute(const std::string& objectPath, const std::string& name) const {
  Where w = attributeWhere(path_, objectPath, name);
  return pathExists(file_, objectPath, w) && attributeExists(file_, objectPath, name, w);
}

std::string Archive::stringAttribute(const std::string& objectPath, const std::string& name) const {
  Where w = attributeWhere(path_, objectPath, name);
  Handle attribute = openScalarAttribute(file_, objectPath, name, w);
  Handle type = w.own(H5Aget_type(attribute.get()), H5Tclose, "cannot read the attribute's datatype");
  requireClass(type.get(), H5T_STRING, "string", w);
  // Read with the stored type itself: HDF5 does not convert between ASCII and UTF-8 strings.
  if (w.check(H5Tis_variable_str(type.get()), "cannot read the attribute's datatype")) {
    char* text = nullptr;
    w.check(H5Aread(attribute.get(), type.get(), &text), "cannot read the attribute");
    std::string value = text ? text : "";
    Handle space = w.own(H5Aget_space(attribute.get()), H5Sclose, "cannot read the attribute's dataspace");
    H5Dvlen_reclaim(type.get(), space.get(), H5P_DEFAULT, &text);
    return value;
  }
  // Fixed-length strings (numpy bytes, other writers): cut at the first NUL.
  std::string value(H5Tget_size(type.get()), '\0');
  w.check(H5Aread(attribute.get(), type.get(), value.data()), "cannot read the attribute");
  return value.substr(0, value.find('\0'));
}

double Archive::doubleAttribute(const std::string& objectPath, const std::string& name) const {
  return readNumericAttribute<double>(file_, objectPath, name, attributeWhere(path_, objectPath, name));
}
int64_t Archive::intAttribute(const std::string& objectPath, const std::string& name) const {
  return readNumericAttribute<int64_t>(file_, objectPath, name, attributeWhere(path_, objectPath, name));
}

void Archive::close() {
  const hid_t file = std::exchange(file_, H5I_INVALID_HID);
  Where{path_, "/"}.check(H5Fclose(file), "cannot close the file");
}

void Archive::flush() { Where{path_, "/"}.check(H5Fflush(file_, H5F_SCOPE_GLOBAL), "cannot flush the file"); }

} // namespace quiver
