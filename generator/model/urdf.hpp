// URDF -> Model (through urdfdom).
#pragma once

#include <string>

#include "model/model.hpp"

namespace proxgen {

/// Largest URDF file read (bytes). Larger files are refused before parsing, so a
/// huge input fails fast with a clear message instead of exhausting memory.
inline constexpr std::size_t kMaxUrdfBytes = 64u << 20;

/// Most markup tags ('<' characters: elements, end tags, comments) read, 256 per
/// link at the link limit; real URDFs have 10 to 40 per link. Counted before any
/// XML parser runs: their DOMs take ~100-200 bytes per node, so this bounds the
/// memory a file of many tiny elements costs (a 63 MB file of `<a/>` took
/// 3.7 GB before); see docs/guarantees.md.
inline constexpr std::size_t kMaxUrdfTags = 1u << 20;

/// Most <link> (and <joint>) elements read: so at most 4095 moving joints and
/// 4101 DoF. Refused right after the XML parse, before urdfdom and the model
/// builder run. The bound that matters is the generic solvers' Data: its dense
/// joint-space matrices take 24 nv^2 bytes (0.4 GB at the limit, 0.1 GB at
/// 2000 DoF); see docs/guarantees.md.
inline constexpr std::size_t kMaxUrdfLinks = 4096;

/// Deepest kinematic tree read (joints, fixed ones included, from the root link
/// to a leaf). Deeper trees are refused before the model is built, which
/// recurses once per level: 1.6 kB of stack per level in a Release build,
/// 7.8 kB under ASan, so 512 levels fit an 8 MB stack with room to spare in
/// both (docs/guarantees.md). Real robots are below 50.
inline constexpr std::size_t kMaxTreeDepth = 512;

/// Deepest XML nesting read, and most attributes on one element and in a whole
/// file. Checked by a scan of the text before either XML parser runs (both
/// TinyXML, inside urdfdom, and tinyxml2 recurse once per level: tinyxml2 stops
/// below 100, TinyXML never, and URDFs nest under 10 deep; and both check
/// an element's attributes for duplicates pairwise: 80,000 attributes on one
/// element took 24 s). URDF elements have at most 6 attributes (<inertia>) and
/// real files under 3 per tag; each attribute costs ~100-200 bytes in each DOM,
/// like a tag, hence the same total as kMaxUrdfTags (docs/guarantees.md).
inline constexpr std::size_t kMaxXmlDepth = 64;
inline constexpr std::size_t kMaxXmlAttributesPerElement = 64;
inline constexpr std::size_t kMaxUrdfAttributes = 1u << 20;

/// Reads a URDF file into a Model. With BaseType::Floating the root link becomes
/// a free-flyer body, with BaseType::Planar a body on a planar joint in the
/// world's x-y plane (joint `root_joint` either way); with BaseType::Fixed it is
/// welded to the world. Throws proxgen::Error ("FILE:LINE: joint 'x': what is
/// wrong") on bad input.
Model loadUrdf(const std::string& path, BaseType base);
/// `floatingBase`: BaseType::Floating, else BaseType::Fixed.
Model loadUrdf(const std::string& path, bool floatingBase);

/// The same from a string already in memory; `path` is only used in messages.
Model parseUrdf(const std::string& xml, const std::string& path, BaseType base);
Model parseUrdf(const std::string& xml, const std::string& path, bool floatingBase);

}  // namespace proxgen
