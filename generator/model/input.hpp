// What every input reader shares: reading a file that must be a regular one,
// and the checks of names and numbers every loader applies (implemented in
// model/model.cpp).
#pragma once

#include <cstddef>
#include <string>

namespace proxgen {

/// Largest magnitude accepted for a number of any input that enters the
/// dynamics: URDF origins, masses and inertias; the layout's gravity, mu,
/// gains, offsets and targets; a state's q, v and tau (quaternion components
/// excepted: only their direction is used). 1e15 is far beyond any robot in SI
/// units (1e15 m is 7000 au; a revolute angle of 1e15 rad is known to 0.1 rad)
/// and keeps any product of up to 20 such inputs finite (1e15^20 = 1e300 <
/// 1.8e308), where 1e308 in gravity or kp overflowed the first product. What
/// the solvers still make non-finite is refused on the output side.
inline constexpr double kMaxInputMagnitude = 1e15;

/// Smallest inertia a moving joint may move about its own axes (kg for a
/// prismatic joint, kg m^2 for a revolute one; the smallest eigenvalue of
/// S^T I_composite S): the solvers divide by it (D_i^-1), so its reciprocal,
/// at most 1e30, stays a factor kMaxInputMagnitude^-1 inside the bound above.
/// A grain of dust (1e-9 kg at 0.1 mm) has 1e-17 kg m^2; bodies of 1e-300 kg,
/// whose reciprocals overflowed, are refused.
inline constexpr double kMinMovedInertia = 1e-30;

/// The whole of an input file, refused unless it is a regular file of at most
/// `maxBytes` (a FIFO, a device or a socket would block or never end; it is
/// opened non-blocking and checked with fstat on the open descriptor, so it
/// cannot be swapped between the check and the read). `kind` names the file
/// in messages ("URDF", "layout", "state", "cases").
std::string readInputFile(const std::string& path, std::size_t maxBytes, const char* kind);

/// Whether `s` is well-formed UTF-8 (no overlong forms, no surrogates, nothing
/// above U+10FFFF). `badOffset` gets the first offending byte's position.
bool isValidUtf8(const std::string& s, std::size_t* badOffset = nullptr);

/// Refuses a name that is not valid UTF-8: names reach JSON output (`check
/// --json`, `eval`), which cannot hold such bytes.
void requireUtf8(const std::string& file, const std::string& element, const std::string& name);

/// Refuses a number beyond kMaxInputMagnitude (or not finite) naming `element`.
double requireMagnitude(const std::string& file, const std::string& element, double x);

}  // namespace proxgen
