// An independent ray tracer for goldray's diagnosis tests: a student's program written apart from
// goldray, with its own single-precision arithmetic, its own parsing of the course's scene format
// and its own PNG writer, so that its pictures differ from goldray's the way a real submission's
// do (rounding, edge pixels, acne drawn in other places).
//
// The course's command line:
//   raytracer -input scene.txt -size W H [-bounces N] [-shadows] [-jitter] [-filter]
//             -output a.png [-normals n.png] [-depth MIN MAX d.png]
// It reads what the tests' scenes use: PerspectiveCamera, Lights (DirectionalLight, PointLight),
// Background (color, ambientLight), Materials (Material / PhongMaterial), Group with MaterialIndex,
// Sphere, Plane, Triangle, Transform (Translate, Scale, UniformScale, X/Y/ZRotate) and nested
// Groups. -jitter and -filter are accepted and ignored, as the course's binary does.
//
// Mistakes are planted with the environment variable PLANT, a comma-separated list:
//   plane, triangle, transform   the starter's intersections as shipped: no hit
//   point-light                  the starter's PointLight::getIllumination: no light
//   background                   a ray that hits nothing is black
//   shading                      the starter's traceRay: the flat diffuse colour
//   specular, shadows, reflections   that part never written
//   acne                         shadow rays start on the surface with tmin = 0
//   depth-miss                   a miss is white in the depth image: the starter's render loop
//                                writes (t - min)/(max - min) for a miss too (t = FLT_MAX), whose
//                                conversion to a code overflows; ARM saturates it to 255
//   starter                      the starter as shipped, as it runs on x86 (where that overflow
//                                writes 0, black as the course's): plane, triangle, transform,
//                                point-light, background and shading at once
//
// Built by the tests with:  c++ -O2 -o raytracer raytracer.cpp
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <memory>
#include <set>
#include <sstream>
#include <string>
#include <vector>

struct V {
    float x = 0, y = 0, z = 0;
};
static V v(float x, float y, float z) { return V{x, y, z}; }
static V operator+(V a, V b) { return v(a.x + b.x, a.y + b.y, a.z + b.z); }
static V operator-(V a, V b) { return v(a.x - b.x, a.y - b.y, a.z - b.z); }
static V operator*(float s, V a) { return v(s * a.x, s * a.y, s * a.z); }
static V mul(V a, V b) { return v(a.x * b.x, a.y * b.y, a.z * b.z); }
static float dot(V a, V b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static V cross(V a, V b) { return v(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x); }
static V unit(V a) { return (1.0f / std::sqrt(dot(a, a))) * a; }

// A 4×4 matrix, row-major, acting on column vectors.
struct M4 {
    float m[4][4] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}};
};
static M4 mul(const M4& a, const M4& b) {
    M4 r;
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++) {
            r.m[i][j] = 0;
            for (int k = 0; k < 4; k++) r.m[i][j] += a.m[i][k] * b.m[k][j];
        }
    return r;
}
static V apply(const M4& a, V p, float w) {
    float in[4] = {p.x, p.y, p.z, w}, out[3];
    for (int i = 0; i < 3; i++) out[i] = a.m[i][0] * in[0] + a.m[i][1] * in[1] + a.m[i][2] * in[2] + a.m[i][3] * in[3];
    return v(out[0], out[1], out[2]);
}
// Gauss–Jordan with partial pivoting; the scenes' transforms are invertible.
static M4 inverse(M4 a) {
    M4 r;
    for (int c = 0; c < 4; c++) {
        int p = c;
        for (int i = c + 1; i < 4; i++)
            if (std::fabs(a.m[i][c]) > std::fabs(a.m[p][c])) p = i;
        std::swap(a.m[c], a.m[p]);
        std::swap(r.m[c], r.m[p]);
        float d = a.m[c][c];
        for (int j = 0; j < 4; j++) a.m[c][j] /= d, r.m[c][j] /= d;
        for (int i = 0; i < 4; i++) {
            if (i == c) continue;
            float f = a.m[i][c];
            for (int j = 0; j < 4; j++) a.m[i][j] -= f * a.m[c][j], r.m[i][j] -= f * r.m[c][j];
        }
    }
    return r;
}

static std::set<std::string> planted;
static bool plants(const char* mistake) { return planted.count(mistake) > 0; }

struct Hit {
    float t = std::numeric_limits<float>::max();
    int material = -1;
    V normal;
};

struct Object {
    virtual ~Object() {}
    virtual bool intersect(V o, V d, float tmin, Hit& h) const = 0;
    int material = 0;
};

struct Sphere : Object {
    V center;
    float radius = 1;
    bool intersect(V o, V d, float tmin, Hit& h) const override {
        V oc = o - center;
        float a = dot(d, d), b = 2 * dot(d, oc), c = dot(oc, oc) - radius * radius;
        float disc = b * b - 4 * a * c;
        if (disc < 0) return false;
        float root = std::sqrt(disc);
        float t = (-b - root) / (2 * a);
        if (t <= tmin) t = (-b + root) / (2 * a);
        if (t <= tmin || t >= h.t) return false;
        h.t = t;
        h.material = material;
        h.normal = unit(o + t * d - center);
        return true;
    }
};

struct Plane : Object {
    V normal;
    float offset = 0;
    bool intersect(V o, V d, float tmin, Hit& h) const override {
        if (plants("plane")) return false;
        float denominator = dot(normal, d);
        if (denominator == 0) return false;
        float t = (offset - dot(normal, o)) / denominator;
        if (t <= tmin || t >= h.t) return false;
        h.t = t;
        h.material = material;
        h.normal = normal;
        return true;
    }
};

struct Triangle : Object {
    V a, b, c;
    bool intersect(V o, V d, float tmin, Hit& h) const override {
        if (plants("triangle")) return false;
        // Möller–Trumbore.
        V e1 = b - a, e2 = c - a, p = cross(d, e2);
        float det = dot(e1, p);
        if (std::fabs(det) < 1e-12f) return false;
        V s = o - a;
        float u = dot(s, p) / det;
        if (u < 0 || u > 1) return false;
        V q = cross(s, e1);
        float w = dot(d, q) / det;
        if (w < 0 || u + w > 1) return false;
        float t = dot(e2, q) / det;
        if (t <= tmin || t >= h.t) return false;
        h.t = t;
        h.material = material;
        h.normal = unit(cross(e1, e2));
        return true;
    }
};

struct Group : Object {
    std::vector<std::unique_ptr<Object>> members;
    bool intersect(V o, V d, float tmin, Hit& h) const override {
        bool hit = false;
        for (const auto& m : members) hit = m->intersect(o, d, tmin, h) || hit;
        return hit;
    }
};

struct Transform : Object {
    M4 inverse_matrix;
    std::unique_ptr<Object> object;
    bool intersect(V o, V d, float tmin, Hit& h) const override {
        if (plants("transform")) return false;
        if (!object->intersect(apply(inverse_matrix, o, 1), apply(inverse_matrix, d, 0), tmin, h)) return false;
        // The normal back to world space by the inverse transpose.
        const auto& m = inverse_matrix.m;
        V n = h.normal;
        h.normal = unit(v(m[0][0] * n.x + m[1][0] * n.y + m[2][0] * n.z, m[0][1] * n.x + m[1][1] * n.y + m[2][1] * n.z,
                          m[0][2] * n.x + m[1][2] * n.y + m[2][2] * n.z));
        return true;
    }
};

struct Light {
    bool point = false;
    V direction, position, color;
    float falloff = 1;
    // The direction to the light, the intensity at p and the distance to the light.
    void illuminate(V p, V& to_light, V& intensity, float& distance) const {
        if (!point) {
            to_light = -1.0f * unit(direction);
            intensity = color;
            distance = std::numeric_limits<float>::max();
        } else if (plants("point-light")) {
            to_light = V{};
            intensity = V{};
            distance = 0;
        } else {
            V offset = position - p;
            distance = std::sqrt(dot(offset, offset));
            to_light = (1.0f / distance) * offset;
            intensity = (1.0f / (falloff * distance * distance)) * color;
        }
    }
};

struct Material {
    V diffuse, specular;
    float shininess = 0;
};

struct Scene {
    V center, direction, up;
    float angle = 30;
    V background = v(0.5f, 0.5f, 0.5f), ambient;
    std::vector<Light> lights;
    std::vector<Material> materials;
    Group group;
};

// Whitespace-separated words, with braces as words of their own.
struct Words {
    std::vector<std::string> words;
    size_t next = 0;
    explicit Words(const std::string& text) {
        std::string spaced;
        for (char c : text) {
            if (c == '{' || c == '}') spaced += std::string(" ") + c + " ";
            else spaced += c;
        }
        std::istringstream in(spaced);
        std::string w;
        while (in >> w) words.push_back(w);
    }
    std::string word() { return next < words.size() ? words[next++] : ""; }
    std::string peek() const { return next < words.size() ? words[next] : ""; }
    float number() { return std::strtof(word().c_str(), nullptr); }
    V vec() {
        float x = number(), y = number();
        return v(x, y, number());
    }
};

static std::unique_ptr<Object> read_object(Words& in, const std::string& kind, int& material);

static void read_group(Words& in, Group& group, int material) {
    in.word();  // {
    while (in.peek() != "}" && !in.peek().empty()) {
        std::string w = in.word();
        if (w == "numObjects") in.word();
        else if (w == "MaterialIndex") material = (int)in.number();
        else group.members.push_back(read_object(in, w, material));
    }
    in.word();  // }
}

static std::unique_ptr<Object> read_object(Words& in, const std::string& kind, int& material) {
    std::unique_ptr<Object> object;
    if (kind == "Group") {
        auto g = std::make_unique<Group>();
        read_group(in, *g, material);
        return g;
    }
    in.word();  // {
    if (kind == "Sphere") {
        auto s = std::make_unique<Sphere>();
        in.word(), s->center = in.vec(), in.word(), s->radius = in.number();
        object = std::move(s);
    } else if (kind == "Plane") {
        auto p = std::make_unique<Plane>();
        in.word(), p->normal = in.vec(), in.word(), p->offset = in.number();
        object = std::move(p);
    } else if (kind == "Triangle") {
        auto t = std::make_unique<Triangle>();
        in.word(), t->a = in.vec(), in.word(), t->b = in.vec(), in.word(), t->c = in.vec();
        object = std::move(t);
    } else if (kind == "Transform") {
        auto t = std::make_unique<Transform>();
        M4 matrix;
        while (true) {
            std::string op = in.word();
            M4 m;
            const float pi = 3.14159265358979f;
            if (op == "Translate") {
                V by = in.vec();
                m.m[0][3] = by.x, m.m[1][3] = by.y, m.m[2][3] = by.z;
            } else if (op == "Scale" || op == "UniformScale") {
                V by = op == "Scale" ? in.vec() : [&] { float s = in.number(); return v(s, s, s); }();
                m.m[0][0] = by.x, m.m[1][1] = by.y, m.m[2][2] = by.z;
            } else if (op == "XRotate" || op == "YRotate" || op == "ZRotate") {
                float r = in.number() * pi / 180, c = std::cos(r), s = std::sin(r);
                int i = op == "XRotate" ? 1 : 0, j = op == "ZRotate" ? 1 : 2;
                m.m[i][i] = c, m.m[j][j] = c;
                m.m[i][j] = op == "YRotate" ? s : -s;
                m.m[j][i] = op == "YRotate" ? -s : s;
            } else {
                t->object = read_object(in, op, material);
                break;
            }
            matrix = mul(matrix, m);  // the first listed is applied last
        }
        t->inverse_matrix = inverse(matrix);
        object = std::move(t);
    } else {
        std::fprintf(stderr, "unsupported object %s\n", kind.c_str());
        std::exit(2);
    }
    object->material = material;
    in.word();  // }
    return object;
}

static Scene read_scene(const std::string& text) {
    Scene scene;
    Words in(text);
    bool lights_given = false;
    for (std::string block = in.word(); !block.empty(); block = in.word()) {
        if (block == "Group") {
            read_group(in, scene.group, 0);
            continue;
        }
        in.word();  // {
        while (in.peek() != "}" && !in.peek().empty()) {
            std::string w = in.word();
            if (w == "center") scene.center = in.vec();
            else if (w == "direction") scene.direction = in.vec();
            else if (w == "up") scene.up = in.vec();
            else if (w == "angle") scene.angle = in.number();
            else if (w == "color") scene.background = in.vec();
            else if (w == "ambientLight") scene.ambient = in.vec();
            else if (w == "numLights") lights_given = true, in.word();
            else if (w == "numMaterials") in.word();
            else if (w == "DirectionalLight" || w == "PointLight") {
                Light light;
                light.point = w == "PointLight";
                in.word();
                while (in.peek() != "}") {
                    std::string field = in.word();
                    if (field == "falloff") light.falloff = in.number();
                    else if (field == "direction") light.direction = in.vec();
                    else if (field == "position") light.position = in.vec();
                    else light.color = in.vec();
                }
                in.word();
                scene.lights.push_back(light);
            } else if (w == "Material" || w == "PhongMaterial") {
                Material m;
                m.diffuse = v(1, 1, 1);
                in.word();
                while (in.peek() != "}") {
                    std::string field = in.word();
                    if (field == "diffuseColor") m.diffuse = in.vec();
                    else if (field == "specularColor") m.specular = in.vec();
                    else m.shininess = in.number();
                }
                in.word();
                scene.materials.push_back(m);
            }
        }
        in.word();  // }
    }
    if (!lights_given || scene.lights.empty()) scene.ambient = v(1, 1, 1);
    return scene;
}

struct Tracer {
    const Scene& scene;
    bool shadows;

    V background() const { return plants("background") ? V{} : scene.background; }

    V trace(V o, V d, float tmin, int bounces, Hit& h) const {
        if (!scene.group.intersect(o, d, tmin, h)) return background();
        const Material& m = scene.materials[h.material];
        if (plants("shading")) return m.diffuse;
        V p = o + h.t * d, n = h.normal, color = mul(scene.ambient, m.diffuse);
        for (const Light& light : scene.lights) {
            V to_light, intensity;
            float distance;
            light.illuminate(p, to_light, intensity, distance);
            if (shadows && !plants("shadows")) {
                Hit blocker;
                bool acne = plants("acne");
                V from = acne ? p : p + 0.01f * to_light;
                if (scene.group.intersect(from, to_light, 0, blocker) && blocker.t < distance) continue;
            }
            float cos_light = dot(to_light, n);
            V reflected = 2 * cos_light * n - to_light;
            float cos_view = std::fmax(dot(reflected, -1.0f * d), 0.0f);
            V shade = std::fmax(cos_light, 0.0f) * m.diffuse;
            if (!plants("specular")) shade = shade + std::pow(cos_view, m.shininess) * m.specular;
            color = color + mul(shade, intensity);
        }
        if (bounces > 0 && std::sqrt(dot(m.specular, m.specular)) > 0.1f && !plants("reflections")) {
            V mirror = d - 2 * dot(d, n) * n;
            Hit next;
            color = color + mul(m.specular, trace(p + 0.01f * mirror, mirror, 0, bounces - 1, next));
        }
        return color;
    }
};

static uint32_t crc32(const uint8_t* bytes, size_t n) {
    uint32_t c = 0xffffffffu;
    for (size_t i = 0; i < n; i++) {
        c ^= bytes[i];
        for (int k = 0; k < 8; k++) c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1)));
    }
    return ~c;
}

static void be32(std::vector<uint8_t>& out, uint32_t x) {
    for (int s = 24; s >= 0; s -= 8) out.push_back(uint8_t(x >> s));
}

static void png_chunk(std::vector<uint8_t>& png, const char* type, const std::vector<uint8_t>& data) {
    be32(png, uint32_t(data.size()));
    size_t from = png.size();
    png.insert(png.end(), type, type + 4);
    png.insert(png.end(), data.begin(), data.end());
    be32(png, crc32(png.data() + from, png.size() - from));
}

// 8-bit RGB, rows top first, in a zlib stream of stored deflate blocks.
static bool save_png(const std::string& path, int w, int h, const std::vector<uint8_t>& rgb) {
    std::vector<uint8_t> raw;
    for (int y = 0; y < h; y++) {
        raw.push_back(0);
        raw.insert(raw.end(), rgb.begin() + size_t(y) * w * 3, rgb.begin() + size_t(y + 1) * w * 3);
    }
    std::vector<uint8_t> z = {0x78, 0x01};
    for (size_t at = 0; at < raw.size() || at == 0;) {
        size_t n = std::min<size_t>(65535, raw.size() - at);
        z.push_back(at + n == raw.size());
        z.push_back(uint8_t(n)), z.push_back(uint8_t(n >> 8));
        z.push_back(uint8_t(~n)), z.push_back(uint8_t(~n >> 8));
        z.insert(z.end(), raw.begin() + at, raw.begin() + at + n);
        at += n;
        if (n == 0) break;
    }
    uint32_t a = 1, b = 0;
    for (uint8_t byte : raw) a = (a + byte) % 65521, b = (b + a) % 65521;
    be32(z, (b << 16) | a);
    std::vector<uint8_t> png = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'}, header;
    be32(header, w), be32(header, h);
    header.insert(header.end(), {8, 2, 0, 0, 0});
    png_chunk(png, "IHDR", header);
    png_chunk(png, "IDAT", z);
    png_chunk(png, "IEND", {});
    FILE* f = std::fopen(path.c_str(), "wb");
    if (!f) return false;
    bool ok = std::fwrite(png.data(), 1, png.size(), f) == png.size();
    return std::fclose(f) == 0 && ok;
}

static uint8_t code(float c) {
    float scaled = c * 255;
    if (!(scaled > 0)) return 0;  // NaN too
    return scaled >= 255 ? 255 : uint8_t(scaled);
}

int main(int argc, char** argv) {
    std::string input, output, normals_file, depth_file;
    int w = 100, h = 100, bounces = 0;
    bool shadows = false;
    float depth_min = 0, depth_max = 1;
    for (int i = 1; i < argc; i++) {
        std::string a = argv[i];
        if (a == "-input" && i + 1 < argc) input = argv[++i];
        else if (a == "-output" && i + 1 < argc) output = argv[++i];
        else if (a == "-normals" && i + 1 < argc) normals_file = argv[++i];
        else if (a == "-size" && i + 2 < argc) w = std::atoi(argv[++i]), h = std::atoi(argv[++i]);
        else if (a == "-depth" && i + 3 < argc) {
            depth_min = std::strtof(argv[++i], nullptr);
            depth_max = std::strtof(argv[++i], nullptr);
            depth_file = argv[++i];
        } else if (a == "-bounces" && i + 1 < argc) bounces = std::atoi(argv[++i]);
        else if (a == "-shadows") shadows = true;
        else if (a == "-jitter" || a == "-filter") {}
        else return std::fprintf(stderr, "unknown flag %s\n", a.c_str()), 2;
    }
    if (const char* list = std::getenv("PLANT")) {
        std::stringstream items(list);
        for (std::string item; std::getline(items, item, ',');) {
            if (item == "starter")
                for (const char* part : {"plane", "triangle", "transform", "point-light", "background", "shading"})
                    planted.insert(part);
            else if (!item.empty()) planted.insert(item);
        }
    }
    std::ifstream file(input);
    if (!file || w < 2 || h < 2) return std::fprintf(stderr, "cannot read %s\n", input.c_str()), 2;
    std::stringstream text;
    text << file.rdbuf();
    Scene scene = read_scene(text.str());
    Tracer tracer{scene, shadows};
    V forward = unit(scene.direction), horizontal = unit(cross(scene.direction, scene.up));
    float distance = 1 / std::tan(scene.angle * 3.14159265358979f / 360);
    std::vector<uint8_t> color(size_t(w) * h * 3), normals(color.size()), depth(color.size());
    for (int y = 0; y < h; y++) {
        float ndc_y = 2 * (y / (h - 1.0f)) - 1;
        for (int x = 0; x < w; x++) {
            float ndc_x = 2 * (x / (w - 1.0f)) - 1;
            V d = unit(distance * forward + ndc_x * horizontal + ndc_y * scene.up);
            Hit hit;
            V c = tracer.trace(scene.center, d, 0, bounces, hit);
            bool missed = hit.material < 0;
            V n = missed ? V{} : hit.normal;
            float z = missed && !plants("depth-miss") ? 0 : (hit.t - depth_min) / (depth_max - depth_min);
            size_t at = (size_t(h - 1 - y) * w + x) * 3;  // row 0 of the file is the top
            float channels[3][3] = {{c.x, c.y, c.z}, {(n.x + 1) / 2, (n.y + 1) / 2, (n.z + 1) / 2}, {z, z, z}};
            for (int k = 0; k < 3; k++) {
                color[at + k] = code(channels[0][k]);
                normals[at + k] = code(channels[1][k]);
                depth[at + k] = code(channels[2][k]);
            }
        }
    }
    bool ok = save_png(output, w, h, color);
    if (!normals_file.empty()) ok = save_png(normals_file, w, h, normals) && ok;
    if (!depth_file.empty()) ok = save_png(depth_file, w, h, depth) && ok;
    if (!ok) return std::fprintf(stderr, "cannot write the pictures\n"), 1;
    return 0;
}
