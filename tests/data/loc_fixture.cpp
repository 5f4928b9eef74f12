// Fixture for the significant-lines counter (tests/harness_test.cpp).
// Expected count: 8 (the lines marked "counts").
#include <cmath>
#pragma once

namespace demo {

/* A block comment
   over three lines
   with code-like text: int x = 1; */
struct Sky {  // counts
  public:
    float radiance = 0.0f;  // counts
};

float Scatter(float mu) {             // counts
    const char* url = "http://a//b";  // counts: "//" inside a string is not a comment
    float phase = 3.0f / (16.0f * 3.14159f) * (1.0f + mu * mu);  // counts
    return phase /* inline block */ * 2.0f;                      // counts
}

}  // namespace demo

int main() {                                       // counts
    return static_cast<int>(demo::Scatter(0.5f));  // counts
}
