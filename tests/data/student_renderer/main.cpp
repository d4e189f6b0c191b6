// A stand-in for a student's ray tracer, for goldray's `run` tests: it takes the course's
// command line exactly as the course binary does (-input scene.txt -size w h [-bounces n]
// [-shadows] [-jitter] [-filter] -output f.png -normals n.png -depth min max d.png), checks that
// the scene and every mesh it names can be read where the course's data/ folder has them, and
// writes plausible PNGs (a gradient of the requested size) with its own small PNG writer.
//
// Built by the tests with:  g++ -O1 -o raytracer main.cpp
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

static uint32_t crc_table[256];

static void make_crc_table() {
    for (uint32_t n = 0; n < 256; n++) {
        uint32_t c = n;
        for (int k = 0; k < 8; k++) c = (c & 1) ? 0xedb88320u ^ (c >> 1) : c >> 1;
        crc_table[n] = c;
    }
}

static uint32_t crc(const std::vector<uint8_t>& bytes, size_t from) {
    uint32_t c = 0xffffffffu;
    for (size_t i = from; i < bytes.size(); i++) c = crc_table[(c ^ bytes[i]) & 0xff] ^ (c >> 8);
    return c ^ 0xffffffffu;
}

static void put32(std::vector<uint8_t>& out, uint32_t v) {
    for (int s = 24; s >= 0; s -= 8) out.push_back((v >> s) & 0xff);
}

static void chunk(std::vector<uint8_t>& png, const char* type, const std::vector<uint8_t>& data) {
    put32(png, data.size());
    size_t start = png.size();
    png.insert(png.end(), type, type + 4);
    png.insert(png.end(), data.begin(), data.end());
    put32(png, crc(png, start));
}

// An 8-bit RGB PNG whose zlib stream holds stored (uncompressed) deflate blocks.
static bool write_png(const std::string& path, int w, int h, int salt) {
    std::vector<uint8_t> raw;
    for (int y = 0; y < h; y++) {
        raw.push_back(0);  // filter: none
        for (int x = 0; x < w; x++) {
            raw.push_back((x * 255) / (w > 1 ? w - 1 : 1));
            raw.push_back((y * 255) / (h > 1 ? h - 1 : 1));
            raw.push_back((salt * 40) & 0xff);
        }
    }
    std::vector<uint8_t> z = {0x78, 0x01};
    size_t pos = 0;
    do {
        size_t n = raw.size() - pos < 65535 ? raw.size() - pos : 65535;
        z.push_back(pos + n == raw.size() ? 1 : 0);
        z.push_back(n & 0xff);
        z.push_back(n >> 8);
        z.push_back(~n & 0xff);
        z.push_back((~n >> 8) & 0xff);
        z.insert(z.end(), raw.begin() + pos, raw.begin() + pos + n);
        pos += n;
    } while (pos < raw.size());
    uint32_t a = 1, b = 0;
    for (uint8_t byte : raw) {
        a = (a + byte) % 65521;
        b = (b + a) % 65521;
    }
    put32(z, (b << 16) | a);
    std::vector<uint8_t> png = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    std::vector<uint8_t> header;
    put32(header, w);
    put32(header, h);
    header.insert(header.end(), {8, 2, 0, 0, 0});
    chunk(png, "IHDR", header);
    chunk(png, "IDAT", z);
    chunk(png, "IEND", {});
    FILE* f = std::fopen(path.c_str(), "wb");
    if (!f) return false;
    bool ok = std::fwrite(png.data(), 1, png.size(), f) == png.size();
    return std::fclose(f) == 0 && ok;
}

static std::string folder_of(const std::string& path) {
    size_t slash = path.rfind('/');
    return slash == std::string::npos ? "" : path.substr(0, slash + 1);
}

int main(int argc, char** argv) {
    std::string input, output, normals, depth;
    int w = 100, h = 100;
    for (int i = 1; i < argc; i++) {
        std::string a = argv[i];
        if (a == "-input" && i + 1 < argc) input = argv[++i];
        else if (a == "-output" && i + 1 < argc) output = argv[++i];
        else if (a == "-normals" && i + 1 < argc) normals = argv[++i];
        else if (a == "-size" && i + 2 < argc) { w = std::atoi(argv[++i]); h = std::atoi(argv[++i]); }
        else if (a == "-depth" && i + 3 < argc) { i += 2; depth = argv[++i]; }
        else if (a == "-bounces" && i + 1 < argc) ++i;
        else if (a == "-shadows" || a == "-jitter" || a == "-filter") {}
        else { std::fprintf(stderr, "unknown flag %s\n", a.c_str()); return 2; }
    }
    std::ifstream scene(input);
    if (!scene) { std::fprintf(stderr, "cannot open the scene %s\n", input.c_str()); return 2; }
    std::stringstream text;
    text << scene.rdbuf();
    std::string word;
    while (text >> word) {
        if (word != "obj_file") continue;
        std::string mesh;
        text >> mesh;
        std::ifstream obj(folder_of(input) + mesh);
        if (!obj) { std::fprintf(stderr, "cannot open the mesh %s\n", mesh.c_str()); return 2; }
    }
    if (w < 1 || h < 1) { std::fprintf(stderr, "bad size\n"); return 2; }
    make_crc_table();
    int salt = 0;
    for (const std::string& out : {output, normals, depth}) {
        salt++;
        if (!out.empty() && !write_png(out, w, h, salt)) {
            std::fprintf(stderr, "cannot write %s\n", out.c_str());
            return 1;
        }
    }
    std::printf("rendered %s at %dx%d\n", input.c_str(), w, h);
    return 0;
}
