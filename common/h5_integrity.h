#pragma once
// Damage detection for the HDF5 files fiberlab writes and reads, so that a
// damaged file gives one line naming it instead of a crash inside HDF5
// (HDF5 1.10 trusts the sizes and addresses it reads from a file).
//
// What protects a file fiberlab writes (h5_file.cpp):
//  - the format bounds "latest" (HDF5 1.10's): superblock, object headers,
//    B-trees, heaps of attributes and the chunk indices carry Jenkins
//    lookup3 checksums, checked by HDF5 on every read;
//  - datasets of fewer than 4096 cells are stored with the Fletcher-32
//    filter; larger ones are deflated (zlib streams end with an Adler-32 of
//    the data, checked by inflate);
//  - the root attribute attribute_digest: a 64-bit FNV-1a digest of every
//    attribute's name and value (attribute_digest below). Variable-length
//    strings (config_yaml, the names) live in HDF5's global heap, which has
//    no checksum; h5py reads fixed-length strings as bytes, so the strings
//    stay variable-length and the digest covers them.
// What nothing here catches: a change made through HDF5 itself (h5py) to a
// file whose attribute_digest was then removed or recomputed (deliberate
// edits are judged by the readers' own checks of shapes, sums and ledger),
// and damage to files written without these protections (any file without
// attribute_digest: older fiberlab versions, other tools), beyond what
// the readers' checks and probe_file's isolation give.
#include <hdf5.h>

#include <cstdint>
#include <string>

namespace fiberlab::h5 {

// The root attribute that holds attribute_digest (uint64).
inline constexpr const char* kDigestAttribute = "attribute_digest";

// FNV-1a (64 bits) over every attribute of every object reachable from the
// root (objects in name order, each one's attributes in name order): the
// object's path, the attribute's name, its type class and its value (strings
// as text, numbers in their native form), except kDigestAttribute itself.
// Throws fiberlab::Error naming `path` if an attribute cannot be read.
std::uint64_t attribute_digest(hid_t file, const std::string& path);

// Reads the whole file's metadata, every attribute and every dataset of at
// most kProbeDatasetBytes, and checks attribute_digest when the file has one;
// in a child process (fork), so that a damaged file that crashes HDF5 kills
// the child, not the caller. Throws fiberlab::Error with one line naming
// `path`: the HDF5 error, the digest mismatch, or that reading it crashed
// or did not finish.
// Called by File::open_read before the file is opened in this process.
void probe_file(const std::string& path);
inline constexpr std::uint64_t kProbeDatasetBytes = std::uint64_t{64} << 20;
// The child's time limit, plus a second per 20 MB of file: HDF5 can also
// loop forever on damaged metadata; a child still reading then is killed
// and the file refused.
inline constexpr double kProbeSeconds = 20.0;

}  // namespace fiberlab::h5
