// gl_renderer.cpp — see gl_renderer.h. The OpenGL 3.3 entry points come
// straight from libGL (GL_GLEXT_PROTOTYPES): on Linux libGL exports the
// core functions, so no loader is needed.
#define GL_GLEXT_PROTOTYPES 1
#include "view/gl_renderer.h"

#include <GL/gl.h>
#include <GL/glext.h>

#include <algorithm>
#include <cstddef>
#include <utility>

namespace sinew::view {
namespace {

const char* kVertexShader = R"(#version 330 core
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec3 a_colour;
uniform mat4 u_model;
uniform mat4 u_view_proj;
uniform float u_point_size;
out vec3 v_position;
out vec3 v_normal;
out vec3 v_colour;
void main() {
  vec4 world = u_model * vec4(a_position, 1.0);
  v_position = world.xyz;
  // The models are rotations with per-axis scales: the inverse transpose
  // keeps the normals of scaled shapes (boxes, capsules) right.
  v_normal = mat3(transpose(inverse(u_model))) * a_normal;
  v_colour = a_colour;
  gl_PointSize = u_point_size;
  gl_Position = u_view_proj * world;
}
)";

const char* kFragmentShader = R"(#version 330 core
in vec3 v_position;
in vec3 v_normal;
in vec3 v_colour;
uniform vec4 u_colour;
uniform bool u_lit;
uniform bool u_vertex_colours;
uniform vec3 u_eye;
out vec4 frag;
void main() {
  vec3 base = u_vertex_colours ? v_colour : u_colour.rgb;
  if (!u_lit) { frag = vec4(base, u_colour.a); return; }
  vec3 n = normalize(v_normal);
  vec3 to_eye = normalize(u_eye - v_position);
  if (dot(n, to_eye) < 0.0) n = -n;  // two-sided: membranes and open surfaces
  // A head light a little above the eye, and a dim fill from above.
  vec3 l = normalize(to_eye + vec3(0.0, 0.35, 0.0));
  float diffuse = max(dot(n, l), 0.0) + 0.25 * max(n.y, 0.0);
  float specular = pow(max(dot(n, normalize(l + to_eye)), 0.0), 48.0);
  frag = vec4(base * (0.18 + 0.8 * diffuse) + vec3(0.25 * specular), u_colour.a);
}
)";

Result<unsigned> compile(GLenum kind, const char* source) {
  const GLuint shader = glCreateShader(kind);
  glShaderSource(shader, 1, &source, nullptr);
  glCompileShader(shader);
  GLint ok = 0;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (ok) return shader;
  char log[2048] = {};
  glGetShaderInfoLog(shader, sizeof log, nullptr, log);
  glDeleteShader(shader);
  return Error{ErrorCode::backend_unavailable, std::string("OpenGL shader does not compile: ") + log};
}

GLenum gl_mode(Primitive p) {
  switch (p) {
    case Primitive::lines: return GL_LINES;
    case Primitive::points: return GL_POINTS;
    case Primitive::triangles: break;
  }
  return GL_TRIANGLES;
}

}  // namespace

GpuMesh::GpuMesh(const MeshData& data, Primitive primitive) : primitive_(primitive) {
  set_vertices(data.vertices);
  set_indices(data.indices);
}

GpuMesh::~GpuMesh() {
  if (vao_) glDeleteVertexArrays(1, &vao_);
  if (vbo_) glDeleteBuffers(1, &vbo_);
  if (ebo_) glDeleteBuffers(1, &ebo_);
}

GpuMesh::GpuMesh(GpuMesh&& o) noexcept { *this = std::move(o); }

GpuMesh& GpuMesh::operator=(GpuMesh&& o) noexcept {
  std::swap(vao_, o.vao_), std::swap(vbo_, o.vbo_), std::swap(ebo_, o.ebo_);
  std::swap(vbo_bytes_, o.vbo_bytes_), std::swap(ebo_bytes_, o.ebo_bytes_);
  std::swap(count_, o.count_), std::swap(primitive_, o.primitive_);
  return *this;
}

void GpuMesh::make() {
  glGenVertexArrays(1, &vao_);
  glGenBuffers(1, &vbo_);
  glGenBuffers(1, &ebo_);
  glBindVertexArray(vao_);
  glBindBuffer(GL_ARRAY_BUFFER, vbo_);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, ebo_);  // kept by the vertex array
  constexpr GLsizei stride = 9 * sizeof(float);
  for (GLuint a = 0; a < 3; ++a) {
    glEnableVertexAttribArray(a);
    glVertexAttribPointer(a, 3, GL_FLOAT, GL_FALSE, stride, reinterpret_cast<const void*>(3 * a * sizeof(float)));
  }
  glBindVertexArray(0);
}

void GpuMesh::set_vertices(std::span<const float> vertices) {
  if (!vao_) make();
  glBindBuffer(GL_ARRAY_BUFFER, vbo_);
  const std::size_t bytes = vertices.size_bytes();
  if (bytes > vbo_bytes_) {
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(bytes), vertices.data(), GL_DYNAMIC_DRAW);
    vbo_bytes_ = bytes;
  } else if (bytes) {
    glBufferSubData(GL_ARRAY_BUFFER, 0, static_cast<GLsizeiptr>(bytes), vertices.data());
  }
}

void GpuMesh::set_indices(std::span<const std::uint32_t> indices) {
  if (!vao_) make();
  glBindVertexArray(vao_);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, ebo_);
  const std::size_t bytes = indices.size_bytes();
  if (bytes > ebo_bytes_) {
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(bytes), indices.data(), GL_DYNAMIC_DRAW);
    ebo_bytes_ = bytes;
  } else if (bytes) {
    glBufferSubData(GL_ELEMENT_ARRAY_BUFFER, 0, static_cast<GLsizeiptr>(bytes), indices.data());
  }
  glBindVertexArray(0);
  count_ = static_cast<int>(indices.size());
}

void GpuMesh::draw() const {
  if (!count_) return;
  glBindVertexArray(vao_);
  glDrawElements(gl_mode(primitive_), count_, GL_UNSIGNED_INT, nullptr);
  glBindVertexArray(0);
}

Status Renderer::init() {
  auto vs = compile(GL_VERTEX_SHADER, kVertexShader);
  if (!vs) return vs.error();
  auto fs = compile(GL_FRAGMENT_SHADER, kFragmentShader);
  if (!fs) return fs.error();
  program_ = glCreateProgram();
  glAttachShader(program_, *vs);
  glAttachShader(program_, *fs);
  glLinkProgram(program_);
  glDeleteShader(*vs);
  glDeleteShader(*fs);
  GLint ok = 0;
  glGetProgramiv(program_, GL_LINK_STATUS, &ok);
  if (!ok) {
    char log[2048] = {};
    glGetProgramInfoLog(program_, sizeof log, nullptr, log);
    return Error{ErrorCode::backend_unavailable, std::string("OpenGL program does not link: ") + log};
  }
  u_model_ = glGetUniformLocation(program_, "u_model");
  u_view_proj_ = glGetUniformLocation(program_, "u_view_proj");
  u_colour_ = glGetUniformLocation(program_, "u_colour");
  u_lit_ = glGetUniformLocation(program_, "u_lit");
  u_vertex_colours_ = glGetUniformLocation(program_, "u_vertex_colours");
  u_eye_ = glGetUniformLocation(program_, "u_eye");
  u_point_size_ = glGetUniformLocation(program_, "u_point_size");
  return {};
}

Renderer::~Renderer() {
  if (program_) glDeleteProgram(program_);
}

void Renderer::begin(int width, int height, const M4& view, const M4& projection, V3 eye, V3 background) {
  glViewport(0, 0, width, height);
  glClearColor(background.x, background.y, background.z, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  glEnable(GL_DEPTH_TEST);
  glDisable(GL_CULL_FACE);  // membranes and cut surfaces are seen from both sides
  glEnable(GL_PROGRAM_POINT_SIZE);
  glEnable(GL_BLEND);
  glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
  glUseProgram(program_);
  const M4 vp = projection * view;
  glUniformMatrix4fv(u_view_proj_, 1, GL_FALSE, vp.m.data());
  glUniform3f(u_eye_, eye.x, eye.y, eye.z);
}

void Renderer::draw(const GpuMesh& mesh, const M4& model, const DrawStyle& style) {
  glUseProgram(program_);
  glUniformMatrix4fv(u_model_, 1, GL_FALSE, model.m.data());
  glUniform4f(u_colour_, style.colour.x, style.colour.y, style.colour.z, style.alpha);
  glUniform1i(u_lit_, style.lit ? 1 : 0);
  glUniform1i(u_vertex_colours_, style.vertex_colours ? 1 : 0);
  glUniform1f(u_point_size_, style.point_size);
  glDepthMask(style.alpha < 1.0f ? GL_FALSE : GL_TRUE);
  if (style.on_top) glDisable(GL_DEPTH_TEST);
  mesh.draw();
  if (style.on_top) glEnable(GL_DEPTH_TEST);
  glDepthMask(GL_TRUE);
}

void Renderer::read_pixels(int width, int height, std::vector<std::uint8_t>& rgb) const {
  std::vector<std::uint8_t> raw(static_cast<std::size_t>(width) * height * 3);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadBuffer(GL_BACK);
  glReadPixels(0, 0, width, height, GL_RGB, GL_UNSIGNED_BYTE, raw.data());
  // OpenGL's rows start at the bottom; images' at the top.
  rgb.resize(raw.size());
  const std::size_t row = static_cast<std::size_t>(width) * 3;
  for (int y = 0; y < height; ++y)
    std::copy_n(&raw[static_cast<std::size_t>(height - 1 - y) * row], row, &rgb[static_cast<std::size_t>(y) * row]);
}

}  // namespace sinew::view
