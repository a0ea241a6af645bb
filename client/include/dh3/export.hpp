#pragma once
// libdh3client is built with hidden visibility: only what carries this mark is
// part of its ABI (the middleware and generated code inside stay private).

#if defined(__GNUC__) || defined(__clang__)
#define DH3_CLIENT_API __attribute__((visibility("default")))
#else
#define DH3_CLIENT_API
#endif
