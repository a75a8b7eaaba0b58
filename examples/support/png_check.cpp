// Checks pixels of a PNG written by the examples:
//     png_check FILE.png X Y R G B [X Y R G B ...]
// Each listed pixel must match within 4 per channel. Exit status 0 when all do.
#include "png.hpp"

#include <cstdio>
#include <cstdlib>
#include <exception>

int main(int argc, char** argv) {
    if (argc < 7 || (argc - 2) % 5 != 0) {
        std::fprintf(stderr, "usage: %s FILE.png X Y R G B [X Y R G B ...]\n", argv[0]);
        return 2;
    }
    try {
        auto image = vkrc_examples::read_png(argv[1]);
        int failures = 0;
        for (int i = 2; i < argc; i += 5) {
            unsigned x = std::atoi(argv[i]), y = std::atoi(argv[i + 1]);
            if (x >= image.width || y >= image.height) {
                std::fprintf(stderr, "pixel (%u, %u) is outside the %ux%u image\n", x, y, image.width, image.height);
                return 1;
            }
            const std::uint8_t* p = image.at(x, y);
            bool ok = true;
            for (int c = 0; c < 3; ++c) ok &= std::abs(p[c] - std::atoi(argv[i + 2 + c])) <= 4;
            std::printf("(%u, %u) = %u %u %u %s\n", x, y, p[0], p[1], p[2], ok ? "ok" : "MISMATCH");
            failures += !ok;
        }
        return failures == 0 ? 0 : 1;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "%s\n", e.what());
        return 1;
    }
}
