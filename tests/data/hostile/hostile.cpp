// Hostile "student programs" for goldray's sandbox tests. `hostile ACTION [EXTRA] -input … -output
// f.png …` does ACTION when the scene is scene01 (other renders behave), then writes each output
// file it was asked for (holding what the action reported, so that anything it managed to read
// or do would reach the test through the delivered file).
//
// Built by the tests with:  g++ -O1 -o hostile hostile.cpp
#include <arpa/inet.h>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <netinet/in.h>
#include <string>
#include <sched.h>
#include <sys/ptrace.h>
#include <sys/socket.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>
#include <vector>

static std::string attempt_write(const std::string& path) {
    FILE* f = std::fopen(path.c_str(), "w");
    if (!f) return "write " + path + ": refused (" + std::strerror(errno) + ")\n";
    std::fputs("escaped\n", f);
    std::fclose(f);
    return "write " + path + ": WROTE\n";
}

static std::string act(const std::string& action, const std::string& extra) {
    if (action == "loop") {
        for (volatile unsigned long i = 0;; i++) {}
    } else if (action == "forkbomb") {
        for (;;) fork();
    } else if (action == "alloc") {
        std::fprintf(stderr, "allocating 20 GB\n");
        std::vector<char> big(20ull << 30, 1);
        return "allocated " + std::to_string(big.size()) + "\n";
    } else if (action == "bigfile") {
        FILE* f = std::fopen("big.bin", "wb");
        std::vector<char> block(1 << 20, 'x');
        for (int i = 0; i < 10240; i++) {
            if (std::fwrite(block.data(), 1, block.size(), f) != block.size()) {
                std::fprintf(stderr, "write failed: %s\n", std::strerror(errno));
                return "short write\n";
            }
        }
        return "wrote 10 GB\n";
    } else if (action == "spew") {
        std::string line(1000, 'y');
        line += '\n';
        for (;;) std::fwrite(line.data(), 1, line.size(), stdout);
    } else if (action == "escape") {
        // EXTRA: the test's stand-in for the TA's home.
        return attempt_write(extra + "/pwned") + attempt_write("../../x") + attempt_write("../escaped") +
               attempt_write("/goldray-escape-test") + attempt_write("/var/tmp/goldray-escape-test");
    } else if (action == "read") {
        // EXTRA: a file in another student's folder.
        std::ifstream in(extra);
        std::string text;
        if (in && std::getline(in, text)) return "read: " + text + "\n";
        return std::string("read ") + extra + ": refused (" + std::strerror(errno) + ")\n";
    } else if (action == "connect") {
        int s = socket(AF_INET, SOCK_STREAM, 0);
        if (s < 0) return std::string("socket: refused (") + std::strerror(errno) + ")\n";
        sockaddr_in to{};
        to.sin_family = AF_INET;
        to.sin_port = htons(std::atoi(extra.c_str()));
        to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
        if (connect(s, reinterpret_cast<sockaddr*>(&to), sizeof to) == 0) {
            (void)!write(s, "hello", 5);
            return "connect: CONNECTED\n";
        }
        return std::string("connect: refused (") + std::strerror(errno) + ")\n";
    } else if (action == "linger") {
        // A grandchild in a session of its own, left behind to write EXTRA two seconds later.
        if (fork() == 0) {
            setsid();
            if (fork() == 0) {
                sleep(2);
                std::ofstream(extra) << "still alive\n";
                _exit(0);
            }
            _exit(0);
        }
        return "left a process behind\n";
    } else if (action == "syscalls") {
        // What kernel exploits start from: each attempt reports whether the kernel let it through.
        auto attempt = [](const char* what, long result) {
            return std::string(what) + (result == -1 ? ": refused (" + std::string(std::strerror(errno)) + ")\n"
                                                     : ": ALLOWED\n");
        };
        std::string said = attempt("unshare", unshare(CLONE_NEWUSER | CLONE_NEWNS));
        said += attempt("ptrace", ptrace(PTRACE_TRACEME, 0, nullptr, nullptr));
        said += attempt("io_uring_setup", syscall(SYS_io_uring_setup, 8, nullptr));
        said += attempt("bpf", syscall(SYS_bpf, 0, nullptr, 0));
        said += attempt("perf_event_open", syscall(SYS_perf_event_open, nullptr, 0, -1, -1, 0));
        said += attempt("userfaultfd", syscall(SYS_userfaultfd, 0));
        said += attempt("keyctl", syscall(SYS_keyctl, 0, 0, 0, 0, 0));
        long child = syscall(SYS_clone, (long)(CLONE_NEWUSER | SIGCHLD), nullptr, nullptr, nullptr, nullptr);
        if (child == 0) _exit(0);
        if (child > 0) waitpid(child, nullptr, 0);
        said += attempt("clone(CLONE_NEWUSER)", child);
        // An ordinary child still works.
        pid_t plain = fork();
        if (plain == 0) _exit(0);
        if (plain > 0) waitpid(plain, nullptr, 0);
        said += std::string("fork: ") + (plain > 0 ? "works\n" : "FAILED\n");
        return said;
    } else if (action == "abort") {
        std::fprintf(stderr, "about to abort\n");
        std::fflush(stderr);
        std::abort();
    } else if (action == "segfault") {
        std::fprintf(stderr, "about to crash\n");
        std::fflush(stderr);
        volatile int* nowhere = nullptr;
        *nowhere = 1;
    } else if (action == "exit3") {
        std::fprintf(stderr, "giving up with code 3\n");
        std::exit(3);
    }
    return "behaved\n";
}

int main(int argc, char** argv) {
    if (argc < 2) return 2;
    std::string action = argv[1], extra, input;
    std::vector<std::string> outputs;
    int i = 2;
    if (i < argc && argv[i][0] != '-') extra = argv[i++];
    for (; i < argc; i++) {
        std::string a = argv[i];
        if (a == "-input" && i + 1 < argc) input = argv[++i];
        else if ((a == "-output" || a == "-normals") && i + 1 < argc) outputs.push_back(argv[++i]);
        else if (a == "-depth" && i + 3 < argc) { i += 2; outputs.push_back(argv[++i]); }
    }
    std::string report = input.find("scene01") != std::string::npos ? act(action, extra) : "behaved\n";
    for (const std::string& out : outputs) std::ofstream(out) << report;
    return 0;
}
