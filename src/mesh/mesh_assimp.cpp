// mesh_assimp.cpp: model files through Assimp, the only file that includes it.
//
// A firewall like io/oiio_guard.h: every extern "C" function catches every
// exception and returns a bb_status with a one-line message. The rest of
// bumpbake sees only bb_mesh.

#include "core/internal.h"
#include "io/safe_file.h"
#include <assimp/DefaultIOSystem.h>
#include <assimp/Exporter.hpp>
#include <assimp/IOStream.hpp>
#include <assimp/IOSystem.hpp>
#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <memory>
#include <stdexcept>
#include <string>
#include <sys/stat.h>
#include <unistd.h>

namespace {

// Assimp's messages may hold line breaks, runs of spaces and bytes of the
// file itself (a corrupt mesh name); ours are one line of printable ASCII.
std::string one_line(const char *s) {
  std::string out;
  for (const unsigned char *c = (const unsigned char *)(s ? s : ""); *c; c++) {
    char ch = (*c < 0x20 || *c > 0x7e) ? (*c == '\n' || *c == '\r' || *c == '\t' ? ' ' : '?')
                                       : (char)*c;
    if (ch == ' ' && (out.empty() || out.back() == ' ')) continue;
    out += ch;
  }
  while (!out.empty() && out.back() == ' ') out.pop_back();
  return out.empty() ? std::string("unknown Assimp error") : out;
}

// ------------------------------------------------------------------ reading

// "missing", "a directory" and "unreadable" before Assimp sees the file,
// which reports all of them as a failed open or a missing reader.
bb_status check_readable(const char *path, size_t *size, bb_error *err) {
  struct stat st;
  if (stat(path, &st) != 0) {
    if (errno == ENOENT || errno == ENOTDIR)
      return bb__fail(err, BB_ERR_IO, "%s: no such file", path);
    return bb__fail(err, BB_ERR_IO, "%s: cannot read: %s", path, std::strerror(errno));
  }
  if (S_ISDIR(st.st_mode)) return bb__fail(err, BB_ERR_IO, "%s: is a directory", path);
  int fd = open(path, O_RDONLY | O_CLOEXEC);
  if (fd < 0) return bb__fail(err, BB_ERR_IO, "%s: cannot read: %s", path, std::strerror(errno));
  close(fd);
  if (st.st_size == 0) return bb__fail(err, BB_ERR_FORMAT, "%s: empty file", path);
  *size = (size_t)st.st_size;
  return BB_OK;
}

// A read budget for one import. Assimp 5.2.4's binary PLY reader, given a
// truncated file, seeks back and re-reads it forever; a real import reads
// its file about once (format detection adds a few hundred bytes per
// reader). So reads past a few times the file's size, or many reads at the
// end of the file, end the import with an exception, which Assimp or
// bb_mesh_load turn into a one-line error instead of a hang.
struct read_budget {
  size_t bytes_left;
  int empty_reads_left;
};

class budget_stream : public Assimp::IOStream {
public:
  budget_stream(Assimp::IOSystem *owner, Assimp::IOStream *inner, read_budget *budget)
      : owner_(owner), inner_(inner), budget_(budget) {}
  ~budget_stream() override { owner_->Close(inner_); }
  size_t Read(void *buffer, size_t size, size_t count) override {
    size_t n = inner_->Read(buffer, size, count);
    size_t bytes = n * size;
    if (bytes > budget_->bytes_left || (n == 0 && --budget_->empty_reads_left < 0))
      throw std::runtime_error("the importer kept re-reading the file (corrupt or truncated?)");
    budget_->bytes_left -= bytes;
    return n;
  }
  size_t Write(const void *, size_t, size_t) override { return 0; }
  aiReturn Seek(size_t offset, aiOrigin origin) override { return inner_->Seek(offset, origin); }
  size_t Tell() const override { return inner_->Tell(); }
  size_t FileSize() const override { return inner_->FileSize(); }
  void Flush() override {}

private:
  Assimp::IOSystem *owner_;
  Assimp::IOStream *inner_;
  read_budget *budget_;
};

// Assimp's default file system, read-only, with every stream on the budget.
class budget_io : public Assimp::IOSystem {
public:
  explicit budget_io(size_t file_size) : budget_{4 * file_size + (1u << 20), 1000} {}
  bool Exists(const char *file) const override { return files_.Exists(file); }
  char getOsSeparator() const override { return files_.getOsSeparator(); }
  Assimp::IOStream *Open(const char *file, const char *mode) override {
    if (!mode || std::strchr(mode, 'w') || std::strchr(mode, 'a')) return nullptr;
    Assimp::IOStream *inner = files_.Open(file, mode);
    return inner ? new budget_stream(&files_, inner, &budget_) : nullptr;
  }
  void Close(Assimp::IOStream *stream) override { delete stream; }

private:
  Assimp::DefaultIOSystem files_;
  read_budget budget_;
};

// Counts of what the merged mesh will hold.
struct mesh_counts {
  size_t vertices = 0, triangles = 0, other_faces = 0;
  bool any_normals = false;
};

mesh_counts count_scene(const aiScene *scene) {
  mesh_counts c;
  for (unsigned i = 0; i < scene->mNumMeshes; i++) {
    const aiMesh *m = scene->mMeshes[i];
    c.vertices += m->mNumVertices;
    for (unsigned f = 0; f < m->mNumFaces; f++)
      (m->mFaces[f].mNumIndices == 3 ? c.triangles : c.other_faces)++;
    c.any_normals = c.any_normals || m->HasNormals();
  }
  return c;
}

// Copies one Assimp mesh into out at vertex offset *v and triangle offset
// *t, advancing both. Points and lines (faces of 1 or 2 indices) are
// dropped; Triangulate has split every polygon already.
bb_status copy_mesh(const char *path, const aiMesh *m, bb_mesh *out, size_t *v, size_t *t,
                    bb_error *err) {
  for (unsigned i = 0; i < m->mNumVertices; i++) {
    const aiVector3D &p = m->mVertices[i];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      return bb__fail(err, BB_ERR_VALUE, "%s: vertex %zu has a NaN or infinite coordinate",
                      path, *v + i);
    float *dst = out->positions + 3 * (*v + i);
    dst[0] = p.x, dst[1] = p.y, dst[2] = p.z;
    if (out->normals && m->HasNormals()) {
      const aiVector3D &n = m->mNormals[i];
      float *nd = out->normals + 3 * (*v + i);
      nd[0] = n.x, nd[1] = n.y, nd[2] = n.z;
    }
  }
  for (unsigned f = 0; f < m->mNumFaces; f++) {
    const aiFace &face = m->mFaces[f];
    if (face.mNumIndices != 3) continue;
    for (int k = 0; k < 3; k++) {
      if (face.mIndices[k] >= m->mNumVertices)
        return bb__fail(err, BB_ERR_FORMAT, "%s: face %u refers to a missing vertex", path, f);
      out->indices[3 * *t + (size_t)k] = (uint32_t)(*v + face.mIndices[k]);
    }
    (*t)++;
  }
  *v += m->mNumVertices;
  return BB_OK;
}

bb_status scene_to_mesh(const char *path, const aiScene *scene, bb_mesh *out, bb_error *err) {
  mesh_counts c = count_scene(scene);
  if (c.triangles == 0)
    return bb__fail(err, BB_ERR_FORMAT, "%s: no triangles (%zu vertices, %zu points or lines)",
                    path, c.vertices, c.other_faces);
  bb_error alloc_err = {{0}};
  bb_status st = bb_mesh_alloc(out, c.vertices, c.triangles, c.any_normals, &alloc_err);
  if (st != BB_OK) return bb__fail(err, st, "%s: %s", path, alloc_err.message);
  size_t v = 0, t = 0;
  for (unsigned i = 0; i < scene->mNumMeshes && st == BB_OK; i++)
    st = copy_mesh(path, scene->mMeshes[i], out, &v, &t, err);
  if (st != BB_OK) bb_mesh_free(out);
  return st;
}

bb_status load_mesh(const char *path, bb_mesh *out, bb_error *err) {
  size_t size = 0;
  bb_status st = check_readable(path, &size, err);
  if (st != BB_OK) return st;
  Assimp::Importer importer;
  importer.SetIOHandler(new budget_io(size)); // the importer owns and deletes it
  // Validation first (Assimp runs it before the other steps), so a corrupt
  // file is refused before post-processing walks its indices; node
  // transforms are applied and the meshes merged by PreTransformVertices.
  // No normals are generated: a model without them gets face normals.
  const unsigned flags = aiProcess_ValidateDataStructure | aiProcess_Triangulate |
                         aiProcess_JoinIdenticalVertices | aiProcess_PreTransformVertices;
  const aiScene *scene = importer.ReadFile(path, flags);
  if (!scene) {
    std::string why = one_line(importer.GetErrorString());
    if (why.find("contains no faces") != std::string::npos)
      return bb__fail(err, BB_ERR_FORMAT, "%s: no triangles (%s)", path, why.c_str());
    return bb__fail(err, BB_ERR_FORMAT, "%s: not a readable model: %s", path, why.c_str());
  }
  if (!scene->HasMeshes())
    return bb__fail(err, BB_ERR_FORMAT, "%s: no triangles (the model holds no mesh)", path);
  return scene_to_mesh(path, scene, out, err);
}

// ------------------------------------------------------------------ writing

struct export_format {
  const char *ext;       // lower case, with the dot
  const char *assimp_id; // Assimp's exporter id
};

// Single-file formats only, so one rename publishes the whole result
// (Assimp's "obj" would write a material file beside it).
const export_format EXPORTS[] = {
    {".obj", "objnomtl"}, {".ply", "plyb"}, {".stl", "stlb"}, {".glb", "glb2"}};

const export_format *find_export(const char *path) {
  const char *slash = std::strrchr(path, '/');
  const char *dot = std::strrchr(slash ? slash + 1 : path, '.');
  if (!dot) return nullptr;
  std::string ext(dot);
  for (char &c : ext) c = (char)std::tolower((unsigned char)c);
  for (const export_format &f : EXPORTS)
    if (ext == f.ext) return &f;
  return nullptr;
}

// An aiScene of one mesh, one material and a root node holding it. The
// scene owns everything it points to (aiScene's destructor frees it).
std::unique_ptr<aiScene> mesh_to_scene(const bb_mesh *m) {
  std::unique_ptr<aiScene> scene(new aiScene());
  scene->mRootNode = new aiNode();
  scene->mMaterials = new aiMaterial *[1] { new aiMaterial() };
  scene->mNumMaterials = 1;
  aiMesh *mesh = new aiMesh();
  scene->mMeshes = new aiMesh *[1] { mesh };
  scene->mNumMeshes = 1;
  scene->mRootNode->mMeshes = new unsigned[1]{0};
  scene->mRootNode->mNumMeshes = 1;

  mesh->mMaterialIndex = 0;
  mesh->mPrimitiveTypes = aiPrimitiveType_TRIANGLE;
  mesh->mNumVertices = (unsigned)m->vertex_count;
  mesh->mVertices = new aiVector3D[m->vertex_count];
  if (m->normals) mesh->mNormals = new aiVector3D[m->vertex_count];
  for (size_t i = 0; i < m->vertex_count; i++) {
    const float *p = m->positions + 3 * i;
    mesh->mVertices[i] = aiVector3D(p[0], p[1], p[2]);
    if (m->normals) {
      const float *n = m->normals + 3 * i;
      mesh->mNormals[i] = aiVector3D(n[0], n[1], n[2]);
    }
  }
  mesh->mNumFaces = (unsigned)m->triangle_count;
  mesh->mFaces = new aiFace[m->triangle_count];
  for (size_t t = 0; t < m->triangle_count; t++) {
    aiFace &face = mesh->mFaces[t];
    face.mNumIndices = 3;
    face.mIndices = new unsigned[3];
    for (int k = 0; k < 3; k++) face.mIndices[k] = m->indices[3 * t + (size_t)k];
  }
  return scene;
}

// Publishes blob at path through the safe write path of internal.h
// (checked writes, fsync, rename; nothing at path on any failure).
bb_status write_blob_safely(const char *path, const aiExportDataBlob *blob, bb_error *err) {
  bb_staged_file f;
  bb_status st = bb__safe_open(&f, path, err);
  if (st != BB_OK) return st;
  bb__safe_write(&f, blob->data, blob->size);
  return bb__safe_commit(&f, err);
}

bb_status check_mesh(const char *path, const bb_mesh *m, bb_error *err) {
  if (!m || !m->positions || !m->indices || m->vertex_count == 0 || m->triangle_count == 0)
    return bb__fail(err, BB_ERR_ARGUMENT, "%s: nothing to write (empty mesh)", path);
  if (m->vertex_count > BB_MAX_MESH_ELEMENTS || m->triangle_count > BB_MAX_MESH_ELEMENTS)
    return bb__fail(err, BB_ERR_SIZE, "%s: mesh over the maximum size", path);
  for (size_t i = 0; i < 3 * m->triangle_count; i++)
    if (m->indices[i] >= m->vertex_count)
      return bb__fail(err, BB_ERR_ARGUMENT, "%s: triangle %zu refers to vertex %u of %zu", path,
                      i / 3, m->indices[i], m->vertex_count);
  return BB_OK;
}

bb_status write_mesh(const char *path, const bb_mesh *m, bb_error *err) {
  const export_format *f = find_export(path);
  if (!f)
    return bb__fail(err, BB_ERR_FORMAT,
                    "%s: unknown model format (use .obj, .ply, .stl or .glb)", path);
  bb_status st = check_mesh(path, m, err);
  if (st != BB_OK) return st;
  std::unique_ptr<aiScene> scene = mesh_to_scene(m);
  Assimp::Exporter exporter;
  // The blob belongs to the exporter; nothing touches the disk until the
  // whole file is in memory.
  const aiExportDataBlob *blob = exporter.ExportToBlob(scene.get(), f->assimp_id);
  if (!blob)
    return bb__fail(err, BB_ERR_IO, "%s: cannot export: %s", path,
                    one_line(exporter.GetErrorString()).c_str());
  return write_blob_safely(path, blob, err);
}

} // namespace

extern "C" {

bb_status bb_mesh_load(const char *path, bb_mesh *out, bb_error *err) {
  if (!out) return bb__fail(err, BB_ERR_ARGUMENT, "bb_mesh_load: out is NULL");
  std::memset(out, 0, sizeof *out);
  if (!path) return bb__fail(err, BB_ERR_ARGUMENT, "bb_mesh_load: path is NULL");
  try {
    return load_mesh(path, out, err);
  } catch (const std::bad_alloc &) {
    bb_mesh_free(out);
    return bb__fail(err, BB_ERR_MEMORY, "%s: out of memory while reading", path);
  } catch (const std::exception &e) {
    bb_mesh_free(out);
    return bb__fail(err, BB_ERR_FORMAT, "%s: %s", path, one_line(e.what()).c_str());
  } catch (...) {
    bb_mesh_free(out);
    return bb__fail(err, BB_ERR_FORMAT, "%s: unknown error while reading", path);
  }
}

bb_status bb_mesh_write(const char *path, const bb_mesh *m, bb_error *err) {
  if (!path) return bb__fail(err, BB_ERR_ARGUMENT, "bb_mesh_write: path is NULL");
  try {
    return write_mesh(path, m, err);
  } catch (const std::bad_alloc &) {
    return bb__fail(err, BB_ERR_MEMORY, "%s: out of memory while writing", path);
  } catch (const std::exception &e) {
    return bb__fail(err, BB_ERR_IO, "%s: cannot write: %s", path, one_line(e.what()).c_str());
  } catch (...) {
    return bb__fail(err, BB_ERR_IO, "%s: cannot write: unknown error", path);
  }
}

} // extern "C"
