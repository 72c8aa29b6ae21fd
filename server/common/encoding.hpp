// The text forms of opaque values: base64url (listing cursors) and the constant-time comparison of the bearer
// token.
#pragma once

#include <string>
#include <string_view>

namespace contactd {

// RFC 4648 base64url without padding, and its inverse (false on a character outside the alphabet).
std::string base64url_encode(std::string_view bytes);
bool base64url_decode(std::string_view text, std::string& bytes);

// Compares in time independent of where the strings differ (the token check).
bool constant_time_equal(std::string_view a, std::string_view b);

}  // namespace contactd
