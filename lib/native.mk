# Murdoch's C outside the simulator, for the top Makefile to include; paths
# are from the top of the repository.
#   make native         builds the .so of each library with C (its .stub,
#                       or the scheduler's .c), beside its .sld in its
#                       family's folder, and bench/c-pingpong
#   make native-clean   removes them, and the C that chibi-ffi wrote

# tools/chibi-cflags names the directory of Chibi's headers, which in the
# private install also holds a newer libc's headers; searched after the
# system's directories, it gives chibi/*.h without mixing the two libcs.
# Expanded late, so that "make deps native" sees the install deps made.
NATIVE_CHIBI_INCLUDE = $(patsubst -I%,%,$(filter -I%,$(shell tools/chibi-cflags)))
NATIVE_CHIBI_CFLAGS = $(addprefix -idirafter ,$(NATIVE_CHIBI_INCLUDE))
NATIVE_CHIBI_HEADERS = $(wildcard $(addsuffix /chibi/*.h,$(NATIVE_CHIBI_INCLUDE)))
NATIVE_CFLAGS ?= -O2 -g -Wall

# Every stub's library, beside its .sld in its family's folder, and the
# scheduler's.
NATIVE_STUBS := $(wildcard lib/murdoch/*/*.stub)
NATIVE_MODULES := $(NATIVE_STUBS:.stub=.so) lib/murdoch/sys/scheduler.so

native: $(NATIVE_MODULES) bench/c-pingpong

# The bindings are .stub files, as Chibi's own libraries' are: from X.stub
# chibi-ffi writes X.c (not kept in git), with the procedures' argument
# checks, their type errors and sexp_init_library.  The C they bind is in
# a file of plain C that the stub includes.  Only the scheduler is C
# written by hand through and through (scheduler.c says why).
lib/murdoch/%.c: lib/murdoch/%.stub
	tools/chibi-ffi $< $@

lib/murdoch/%.so: lib/murdoch/%.c $(NATIVE_CHIBI_HEADERS)
	$(CC) $(NATIVE_CFLAGS) $(NATIVE_CHIBI_CFLAGS) -shared -fPIC -o $@ $< \
	    $(NATIVE_LIBS_$(notdir $*))

# The plain C that a stub includes.
lib/murdoch/sys/guard.so: lib/murdoch/sys/heap-watch.c
lib/murdoch/wire/hmac.so: lib/murdoch/wire/hmac-sha256.c
lib/murdoch/wire/netstring.so: lib/murdoch/wire/netstring-scan.c lib/murdoch/wire/plain-read.c
lib/murdoch/code/sendable.so: lib/murdoch/code/plain.c
lib/murdoch/code/sandbox.so: lib/murdoch/code/call-bindings.c
lib/murdoch/wire/connect.so: lib/murdoch/wire/nonblocking-connect.c
lib/murdoch/wire/multicast.so: lib/murdoch/wire/multicast-socket.c

# Kept, so that a look at what chibi-ffi wrote needs no rebuild.
.SECONDARY: $(NATIVE_STUBS:.stub=.c)

# HMAC-SHA256 and the constant-time comparison are OpenSSL's.
NATIVE_LIBS_hmac = -lcrypto

bench/c-pingpong: bench/c-pingpong.c
	$(CC) $(NATIVE_CFLAGS) -o $@ bench/c-pingpong.c

native-clean:
	rm -f $(NATIVE_MODULES) $(NATIVE_STUBS:.stub=.c) bench/c-pingpong

.PHONY: native native-clean
