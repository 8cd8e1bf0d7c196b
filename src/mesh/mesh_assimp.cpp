// mesh_assimp.cpp: model files through Assimp, the only file that includes it.
//
// A firewall like image/oiio_guard.h: every extern "C" function catches every
// exception and returns a bb_status with a one-line message. The rest of
// bumpbake sees only bb_mesh. Reading here is the import itself, confined
// to the model's directory; mesh_load.c runs it in a child process.

#include "core/input_file.h"
#include "core/file_names.h"
#include "core/internal.h"
#include "core/sanitizer_options.h"
#include "files/safe_file.h"
#include "mesh/mesh_import.h"
#include "mesh/mesh_internal.h"
#include <assimp/Exporter.hpp>
#include <assimp/IOStream.hpp>
#include <assimp/IOSystem.hpp>
#include <assimp/Importer.hpp>
#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <cctype>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <memory>
#include <set>
#include <stdexcept>
#include <string>
#include <sys/stat.h>
#include <unistd.h>
#include <utility>
#include <vector>
#ifdef BB_ASAN_BUILD
#include <sanitizer/lsan_interface.h>
#endif

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

// ------------------------------------------------------------------ paths

// The directory part of path: "." when it has none.
std::string directory_of(const std::string &path) {
  size_t slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  return slash == 0 ? std::string("/") : path.substr(0, slash);
}

bool path_exists(const std::string &path) {
  struct stat st;
  return stat(path.c_str(), &st) == 0;
}

// path made absolute and free of symbolic links, ".", ".." and repeated
// slashes: each existing prefix by realpath, the names past the last
// existing one by name, so a file that does not exist still has a place
// to check. False (errno set) when the current directory is unknown or a
// link cannot be followed (a loop, no permission to look).
bool resolve(const std::string &path, std::string *out) {
  if (path.empty()) {
    errno = ENOENT;
    return false;
  }
  std::string abs = path;
  if (path[0] != '/') {
    char cwd[PATH_MAX];
    if (!getcwd(cwd, sizeof cwd)) return false;
    abs = std::string(cwd) + "/" + path;
  }
  std::string done = "/";
  bool exists = true;
  for (size_t i = 0; i <= abs.size();) {
    size_t j = abs.find('/', i);
    if (j == std::string::npos) j = abs.size();
    std::string part = abs.substr(i, j - i);
    i = j + 1;
    if (part.empty() || part == ".") continue;
    if (part == "..") {
      size_t cut = done.find_last_of('/');
      done = cut == 0 ? std::string("/") : done.substr(0, cut);
      // Back on an existing directory, links count again.
      exists = path_exists(done);
      continue;
    }
    std::string next = done == "/" ? "/" + part : done + "/" + part;
    if (exists) {
      char real[PATH_MAX];
      if (realpath(next.c_str(), real)) {
        done = real;
        continue;
      }
      if (errno != ENOENT && errno != ENOTDIR) return false;
      exists = false;
    }
    done = next;
  }
  *out = done;
  return true;
}

// Whether the resolved path lies in the resolved directory root.
bool inside(const std::string &root, const std::string &path) {
  if (root == "/") return true;
  return path.compare(0, root.size(), root) == 0 &&
         (path.size() == root.size() || path[root.size()] == '/');
}

// ------------------------------------------------------------------ reading

// What one import may read and what it was refused. A model may read its
// own file and regular files inside its own directory (resolved: no ".."
// out of it, no absolute path elsewhere, no link out), at most
// BB_MAX_MODEL_BYTES together. Any other file it names ends the import
// with an error, except a file that does not exist, which the importer
// does without when its format allows (an OBJ's .mtl) and which the load
// reports as a note.
//
// The read budget: Assimp 5.2.4's binary PLY reader, given a truncated
// file, seeks back and re-reads it forever; a real import reads each file
// about once (format detection adds a few hundred bytes per reader). So
// reads past four times the files' bytes (and 1 MiB), or many reads at the
// end of a file, end the import with an exception, which Assimp or
// bb__mesh_import turn into a one-line error instead of a hang.
class file_stream;
struct io_state {
  std::string root, model;  // resolved
  std::string given_dir;    // the model's directory as the caller wrote it, with '/'
  std::set<file_stream *> open;
  std::set<std::pair<dev_t, ino_t>> counted;
  size_t bytes = 0;
  size_t read_left = (size_t)1 << 20;
  int empty_reads_left = 1000;
  bb_status refusal_status = BB_OK;
  std::string refusal;               // the first reason the import fails
  std::vector<std::string> missing;  // names of missing files, in order
  std::set<std::string> found;       // base names of the files opened

  void refuse(bb_status status, const std::string &why) {
    if (refusal.empty()) refusal_status = status, refusal = why;
  }
  // A name as the model wrote it: Assimp prefixes the model's directory.
  std::string shown(const char *file) const {
    std::string name = file;
    if (!given_dir.empty() && name.compare(0, given_dir.size(), given_dir) == 0)
      name.erase(0, given_dir.size());
    return one_line(name.c_str());
  }
  void note_missing(const std::string &name) {
    for (const std::string &m : missing)
      if (m == name) return;
    if (missing.size() < 64) missing.push_back(name);
  }
};

static std::string base_name(const std::string &path) {
  size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

class file_stream : public Assimp::IOStream {
public:
  file_stream(std::shared_ptr<io_state> state, FILE *f, size_t size)
      : state_(std::move(state)), f_(f), size_(size) {
    state_->open.insert(this);
  }
  // Assimp closes some streams through IOSystem::Close and deletes others
  // itself (glTF's shared_ptr); either way the stream leaves the set.
  ~file_stream() override {
    state_->open.erase(this);
    std::fclose(f_);
  }
  size_t Read(void *buffer, size_t size, size_t count) override {
    size_t n = size && count ? std::fread(buffer, size, count, f_) : 0;
    size_t bytes = n * size;
    if (bytes > state_->read_left || (n == 0 && --state_->empty_reads_left < 0))
      throw std::runtime_error("the importer kept re-reading the file (corrupt or truncated?)");
    state_->read_left -= bytes;
    return n;
  }
  size_t Write(const void *, size_t, size_t) override { return 0; }
  aiReturn Seek(size_t offset, aiOrigin origin) override {
    // Offsets from the current place or the end come as size_t: negative
    // ones wrap, as in Assimp's own stream.
    int whence = origin == aiOrigin_SET ? SEEK_SET : origin == aiOrigin_CUR ? SEEK_CUR : SEEK_END;
    return fseeko(f_, (off_t)(long)offset, whence) == 0 ? aiReturn_SUCCESS : aiReturn_FAILURE;
  }
  size_t Tell() const override {
    off_t at = ftello(f_);
    return at < 0 ? 0 : (size_t)at;
  }
  size_t FileSize() const override { return size_; }
  void Flush() override {}

private:
  std::shared_ptr<io_state> state_;
  FILE *f_;
  size_t size_;
};

class confined_io : public Assimp::IOSystem {
public:
  explicit confined_io(std::shared_ptr<io_state> state) : state_(std::move(state)) {}
  // Assimp forgets streams on some error paths (the OBJ reader throws
  // between opening a .mtl and closing it); they end with the import.
  ~confined_io() override {
    std::set<file_stream *> left = state_->open;
    for (file_stream *s : left) delete s;
  }
  bool Exists(const char *file) const override {
    std::string real;
    return admit(file, &real) && path_exists(real);
  }
  char getOsSeparator() const override { return '/'; }
  Assimp::IOStream *Open(const char *file, const char *mode) override;
  void Close(Assimp::IOStream *stream) override { delete stream; }

private:
  bool admit(const char *file, std::string *real) const;
  bool opened_inside(int fd) const;
  std::shared_ptr<io_state> state_;
};

// Whether the import may look at file: resolved into *real, it is the
// model or lies in the model's directory. Anything else is refused for the
// whole import, asked by Exists or by Open.
bool confined_io::admit(const char *file, std::string *real) const {
  if (!file) return false;
  const std::string name = state_->shown(file);
  if (!resolve(file, real)) {
    state_->refuse(BB_ERR_IO, "refers to " + name + ", which cannot be resolved: " +
                                  std::strerror(errno));
    return false;
  }
  if (*real == state_->model || inside(state_->root, *real)) return true;
  state_->refuse(BB_ERR_IO, "refers to " + name + ", outside the model's directory");
  return false;
}

// The file a descriptor reached, as the kernel names it: a link swapped in
// between the check and the open shows here. Without /proc the check
// before the open stands alone.
bool confined_io::opened_inside(int fd) const {
  char link[64], target[PATH_MAX];
  std::snprintf(link, sizeof link, "/proc/self/fd/%d", fd);
  ssize_t n = readlink(link, target, sizeof target - 1);
  if (n <= 0) return true;
  target[n] = '\0';
  return state_->model == target || inside(state_->root, target);
}

Assimp::IOStream *confined_io::Open(const char *file, const char *mode) {
  if (!file || !mode || std::strpbrk(mode, "wa+")) return nullptr;
  std::string real;
  if (!admit(file, &real)) return nullptr;
  const std::string name = state_->shown(file);
  struct stat st;
  if (stat(real.c_str(), &st) != 0 && (errno == ENOENT || errno == ENOTDIR)) {
    state_->note_missing(name);
    return nullptr;
  }
  int fd = -1;
  bb_error e = {{0}};
  if (bb__input_open(real.c_str(), &fd, &e) != BB_OK) {
    // e says "REAL: is a FIFO, not a regular file" or "REAL: cannot read: ..."
    std::string why = e.message;
    if (why.compare(0, real.size() + 2, real + ": ") == 0) why.erase(0, real.size() + 2);
    if (why.compare(0, 13, "cannot read: ") == 0) why = "cannot be read: " + why.substr(13);
    state_->refuse(BB_ERR_IO, "refers to " + name + ", which " + why);
    return nullptr;
  }
  if (!opened_inside(fd) || fstat(fd, &st) != 0) {
    close(fd);
    state_->refuse(BB_ERR_IO, "refers to " + name + ", outside the model's directory");
    return nullptr;
  }
  if (state_->counted.insert({st.st_dev, st.st_ino}).second) {
    state_->bytes += (size_t)st.st_size;
    state_->read_left += 4 * (size_t)st.st_size;
    if (state_->bytes > (size_t)BB_MAX_MODEL_BYTES) {
      close(fd);
      state_->refuse(BB_ERR_SIZE, "refers to " + name + ", which takes the model's files over " +
                                      std::to_string(BB_MAX_MODEL_BYTES >> 20) + " MiB");
      return nullptr;
    }
  }
  FILE *f = fdopen(fd, "rb");
  if (!f) {
    close(fd);
    throw std::bad_alloc();
  }
  state_->found.insert(base_name(real));
  return new file_stream(state_, f, (size_t)st.st_size);
}

// In sanitizer builds, what Assimp allocates while it imports (in this
// thread) is not a leak to LeakSanitizer: its readers lose memory on some
// error paths (glTF's base64 decoder throws past the buffer it allocated).
// bb__mesh_load imports in a child process that exits, so nothing it loses
// reaches the caller; this scope keeps those losses from failing the
// in-process import that fuzzing and tests run, while bumpbake's own
// allocations before and after the import stay counted (the streams the
// import opens are tracked and closed by confined_io either way).
class assimp_leak_scope {
public:
  assimp_leak_scope() {
#ifdef BB_ASAN_BUILD
    __lsan_disable();
#endif
  }
  ~assimp_leak_scope() {
#ifdef BB_ASAN_BUILD
    __lsan_enable();
#endif
  }
  assimp_leak_scope(const assimp_leak_scope &) = delete;
  assimp_leak_scope &operator=(const assimp_leak_scope &) = delete;
};

// ------------------------------------------------------------------ scene

// Triangles of one mesh once Triangulate has split its polygons.
double mesh_triangles(const aiMesh *m) {
  double t = 0.0;
  for (unsigned f = 0; f < m->mNumFaces; f++)
    if (m->mFaces[f].mNumIndices >= 3) t += m->mFaces[f].mNumIndices - 2;
  return t;
}

// The triangles and vertices the merged mesh will have: PreTransformVertices
// places a copy of a mesh for every node that uses it, so a small file can
// name a great many. Walked with a stack of our own, not by recursion: the
// node tree is as deep as the importer made it. False when it is over the
// limits (or holds more nodes than memory could: a cycle). Counting costs
// one visit per node; nothing is built.
bool instanced_size_ok(const aiScene *scene, double *triangles, double *vertices) {
  std::vector<double> per_mesh(scene->mNumMeshes);
  for (unsigned i = 0; i < scene->mNumMeshes; i++) per_mesh[i] = mesh_triangles(scene->mMeshes[i]);
  std::vector<const aiNode *> stack{scene->mRootNode};
  size_t visited = 0;
  *triangles = *vertices = 0.0;
  while (!stack.empty()) {
    const aiNode *node = stack.back();
    stack.pop_back();
    if (!node) continue;
    if (++visited > ((size_t)1 << 26)) return false;
    for (unsigned k = 0; k < node->mNumMeshes; k++) {
      unsigned m = node->mMeshes[k];
      if (m >= scene->mNumMeshes) continue; // validation refused these already
      *triangles += per_mesh[m];
      *vertices += scene->mMeshes[m]->mNumVertices;
    }
    for (unsigned c = 0; c < node->mNumChildren; c++) stack.push_back(node->mChildren[c]);
  }
  return *triangles <= (double)BB_MAX_MODEL_TRIANGLES &&
         *vertices <= 3.0 * (double)BB_MAX_MODEL_TRIANGLES;
}

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

bb_status over_limits(const char *path, double triangles, double vertices, bb_error *err) {
  return bb__fail(err, BB_ERR_SIZE,
                  "%s: %.0f triangles and %.0f vertices once placed, over the %ld triangles "
                  "(and three times as many vertices) a model may have",
                  path, triangles, vertices, (long)BB_MAX_MODEL_TRIANGLES);
}

bb_status scene_to_mesh(const char *path, const aiScene *scene, bb_mesh *out, bb_error *err) {
  mesh_counts c = count_scene(scene);
  if (c.triangles == 0)
    return bb__fail(err, BB_ERR_FORMAT, "%s: no triangles (%zu vertices, %zu points or lines)",
                    path, c.vertices, c.other_faces);
  if (c.triangles > (size_t)BB_MAX_MODEL_TRIANGLES ||
      c.vertices > 3 * (size_t)BB_MAX_MODEL_TRIANGLES)
    return over_limits(path, (double)c.triangles, (double)c.vertices, err);
  bb_error alloc_err = {{0}};
  bb_status st = bb__mesh_alloc(out, c.vertices, c.triangles, c.any_normals, &alloc_err);
  if (st != BB_OK) return bb__fail(err, st, "%s: %s", path, alloc_err.message);
  size_t v = 0, t = 0;
  for (unsigned i = 0; i < scene->mNumMeshes && st == BB_OK; i++)
    st = copy_mesh(path, scene->mMeshes[i], out, &v, &t, err);
  if (st != BB_OK) bb__mesh_free(out);
  return st;
}

// "read without a.mtl, b.mtl (no such files)", or "" when nothing was
// missing. Readers try more than one name for a file (glTF: the model's
// directory and the name, then the name alone); a missing name whose base
// name was then opened under another was found, not missed.
std::string missing_note(const io_state &s) {
  std::vector<std::string> missed;
  for (const std::string &m : s.missing)
    if (!s.found.count(base_name(m))) missed.push_back(m);
  if (missed.empty()) return "";
  std::string names;
  for (size_t i = 0; i < missed.size() && i < 3; i++) names += (i ? ", " : "") + missed[i];
  if (missed.size() > 3) names += " and " + std::to_string(missed.size() - 3) + " more";
  return "read without " + names + (missed.size() > 1 ? " (no such files)" : " (no such file)");
}

bb_status load_mesh(const char *path, bb_mesh *out, std::string *note, bb_error *err) {
  size_t size = 0;
  bb_status st = bb__mesh_check_model(path, &size, err);
  if (st != BB_OK) return st;
  auto state = std::make_shared<io_state>();
  if (std::strchr(path, '/')) state->given_dir = directory_of(path) + "/";
  if (!resolve(directory_of(path), &state->root) || !resolve(path, &state->model))
    return bb__fail(err, BB_ERR_IO, "%s: cannot resolve its directory: %s", path,
                    std::strerror(errno));
  Assimp::Importer importer;
  importer.SetIOHandler(new confined_io(state)); // the importer owns and deletes it
  // A file of bones and no mesh (Collada, BVH, MD5, SMD...) would get a
  // stand-in mesh drawn around its joints: not the model's surface.
  importer.SetPropertyBool(AI_CONFIG_IMPORT_NO_SKELETON_MESHES, true);
  // Read and validate only, so the scene's size is checked before
  // post-processing multiplies it; then the steps run as ReadFile would
  // have run them: validation first (a corrupt file is refused before
  // post-processing walks its indices), node transforms applied and the
  // meshes merged by PreTransformVertices. No normals are generated: a
  // model without them gets face normals.
  const aiScene *scene;
  {
    assimp_leak_scope scope;
    scene = importer.ReadFile(path, aiProcess_ValidateDataStructure);
  }
  if (!state->refusal.empty())
    return bb__fail(err, state->refusal_status, "%s: %s", path, state->refusal.c_str());
  if (!scene) {
    std::string why = one_line(importer.GetErrorString());
    if (why.find("bad_alloc") != std::string::npos) throw std::bad_alloc(); // caught by Assimp
    if (why.find("contains no faces") != std::string::npos)
      return bb__fail(err, BB_ERR_FORMAT, "%s: no triangles (%s)", path, why.c_str());
    return bb__fail(err, BB_ERR_FORMAT, "%s: not a readable model: %s", path, why.c_str());
  }
  if (!scene->HasMeshes())
    return bb__fail(err, BB_ERR_FORMAT, "%s: no triangles (the model holds no mesh)", path);
  double triangles = 0.0, vertices = 0.0;
  if (!instanced_size_ok(scene, &triangles, &vertices))
    return over_limits(path, triangles, vertices, err);
  {
    assimp_leak_scope scope;
    scene = importer.ApplyPostProcessing(aiProcess_Triangulate |
                                         aiProcess_JoinIdenticalVertices |
                                         aiProcess_PreTransformVertices);
  }
  if (!scene) {
    std::string why = one_line(importer.GetErrorString());
    if (why.find("bad_alloc") != std::string::npos) throw std::bad_alloc();
    return bb__fail(err, BB_ERR_FORMAT, "%s: not a readable model: %s", path, why.c_str());
  }
  st = scene_to_mesh(path, scene, out, err);
  if (st == BB_OK) *note = missing_note(*state);
  return st;
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
  const char *dot = bb__file_extension(path);
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

bb_status bb__mesh_check_model(const char *path, size_t *size, bb_error *err) {
  int fd = -1;
  bb_status st = bb__input_open(path, &fd, err);
  if (st != BB_OK) return st;
  struct stat s;
  int failed = fstat(fd, &s) != 0 ? errno : 0;
  close(fd);
  if (failed) return bb__fail(err, BB_ERR_IO, "%s: cannot read: %s", path, std::strerror(failed));
  if (s.st_size == 0) return bb__fail(err, BB_ERR_FORMAT, "%s: empty file", path);
  if (s.st_size > BB_MAX_MODEL_BYTES)
    return bb__fail(err, BB_ERR_SIZE, "%s: %.1f MiB, over the %ld MiB a model may have", path,
                    (double)s.st_size / (1 << 20), (long)(BB_MAX_MODEL_BYTES >> 20));
  *size = (size_t)s.st_size;
  return BB_OK;
}

bb_status bb__mesh_import(const char *path, bb_mesh *out, char *note, size_t cap,
                          bb_error *err) {
  if (note && cap) note[0] = '\0';
  if (!out) return bb__fail(err, BB_ERR_ARGUMENT, "bb__mesh_load: out is NULL");
  std::memset(out, 0, sizeof *out);
  if (!path) return bb__fail(err, BB_ERR_ARGUMENT, "bb__mesh_load: path is NULL");
  try {
    std::string said;
    bb_status st = load_mesh(path, out, &said, err);
    if (st == BB_OK && note && cap) std::snprintf(note, cap, "%s", said.c_str());
    return st;
  } catch (const std::bad_alloc &) {
    bb__mesh_free(out);
    return bb__fail(err, BB_ERR_MEMORY, "%s: out of memory while reading", path);
  } catch (const std::exception &e) {
    bb__mesh_free(out);
    return bb__fail(err, BB_ERR_FORMAT, "%s: %s", path, one_line(e.what()).c_str());
  } catch (...) {
    bb__mesh_free(out);
    return bb__fail(err, BB_ERR_FORMAT, "%s: unknown error while reading", path);
  }
}

bb_status bb__mesh_write(const char *path, const bb_mesh *m, bb_error *err) {
  if (!path) return bb__fail(err, BB_ERR_ARGUMENT, "bb__mesh_write: path is NULL");
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
