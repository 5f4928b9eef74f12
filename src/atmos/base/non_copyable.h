// atmos: the base of the objects that must not be copied or moved (a scope
// that restores a setting when it ends, a held lock, a progress bar).
#pragma once

namespace atmos {

class NonCopyable {
  public:
    NonCopyable(const NonCopyable&) = delete;
    NonCopyable& operator=(const NonCopyable&) = delete;

  protected:
    NonCopyable() = default;
    ~NonCopyable() = default;
};

}  // namespace atmos
