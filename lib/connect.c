/*  connect.c -- the C of (murdoch connect): a TCP connect that does not wait
 *
 *  (chibi net)'s open-net-io connects in blocking mode: a host that drops
 *  our SYN holds the whole process, every green thread, for the kernel's
 *  minutes of retries.  Here the connect is non-blocking, and lib/connect.scm
 *  asks every millisecond whether it is done, sleeping its own thread only.
 *
 *  The socket is a plain int until it is connected, and only then becomes
 *  a Chibi fileno, owned by two ports.  A fileno closes its number when
 *  collected unless marked closed, and close-file-descriptor does not mark
 *  it; so a socket that fails is closed here, by number, and no fileno ever
 *  knows it: nothing can close that number again once another socket has
 *  taken it.
 */

#include <chibi/eval.h>
#include <ctype.h>
#include <errno.h>
#include <netdb.h>
#include <poll.h>
#include <stdio.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

/* Why a connect failed, as a Scheme string starting lowercase, so that the
 * caller can put it after "cannot connect to HOST:PORT: ". */
static sexp reason (sexp ctx, const char *text) {
  char buf[128];
  snprintf(buf, sizeof buf, "%s", text);
  buf[0] = tolower((unsigned char)buf[0]);
  return sexp_c_string(ctx, buf, -1);
}

/* The first IPv4 address of host, port, for a stream socket; NULL and a
 * reason in *why when there is none.  getaddrinfo may ask DNS, which blocks
 * the process: names in a lab are addresses or in /etc/hosts. */
static struct addrinfo *resolve (sexp ctx, sexp host, sexp port, sexp *why) {
  struct addrinfo hints, *found;
  char service[8];
  int err;
  memset(&hints, 0, sizeof hints);
  hints.ai_family = AF_INET;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_NUMERICSERV;
  snprintf(service, sizeof service, "%ld", (long)sexp_unbox_fixnum(port));
  err = getaddrinfo(sexp_string_data(host), service, &hints, &found);
  if (err == 0) return found;
  if (err == EAI_NONAME)
    *why = reason(ctx, "no such host");
  else if (err == EAI_SYSTEM)
    *why = reason(ctx, strerror(errno));
  else
    *why = reason(ctx, gai_strerror(err));
  return NULL;
}

/* (connect-start HOST PORT): a socket whose connect to HOST:PORT is under
 * way or done, as an int, or a string saying why there is none.  The
 * socket stays non-blocking: Chibi's ports on it then block only the
 * thread that reads or writes.  Close-on-exec, so that a child process the
 * caller starts later does not hold the connection open. */
static sexp connect_start (sexp ctx, sexp self, sexp_sint_t n,
                           sexp host, sexp port) {
  struct addrinfo *addr;
  sexp why = SEXP_FALSE;
  int fd, err;
  sexp_assert_type(ctx, sexp_stringp, SEXP_STRING, host);
  sexp_assert_type(ctx, sexp_fixnump, SEXP_FIXNUM, port);
  if (sexp_unbox_fixnum(port) < 1 || sexp_unbox_fixnum(port) > 65535)
    return sexp_user_exception(ctx, self, "not a TCP port", port);
  addr = resolve(ctx, host, port, &why);
  if (!addr) return why;
  fd = socket(addr->ai_family,
              addr->ai_socktype | SOCK_NONBLOCK | SOCK_CLOEXEC,
              addr->ai_protocol);
  if (fd < 0) {
    err = errno;
    freeaddrinfo(addr);
    return reason(ctx, strerror(err));
  }
  /* EINTR leaves the connect going on, as EINPROGRESS does. */
  err = connect(fd, addr->ai_addr, addr->ai_addrlen) < 0 ? errno : 0;
  freeaddrinfo(addr);
  if (err != 0 && err != EINPROGRESS && err != EINTR) {
    close(fd);
    return reason(ctx, strerror(err));
  }
  return sexp_make_fixnum(fd);
}

/* The socket, connected, as (in out): ports with shutdown on close, which
 * share one fileno, so that closing both closes the socket once. */
static sexp connection_ports (sexp ctx, sexp self, int fd) {
  sexp_gc_var3(fileno, in, out);
  sexp_gc_preserve3(ctx, fileno, in, out);
  fileno = out = sexp_make_fileno(ctx, sexp_make_fixnum(fd), SEXP_FALSE);
  if (sexp_exceptionp(fileno))
    close(fd);                  /* no fileno owns it: close it here */
  else if (!sexp_exceptionp(in = sexp_open_input_file_descriptor(
                               ctx, self, 2, fileno, SEXP_TRUE)))
    out = sexp_open_output_file_descriptor(ctx, self, 2, fileno, SEXP_TRUE);
  else
    out = in;
  if (!sexp_exceptionp(out))
    out = sexp_list2(ctx, in, out);
  sexp_gc_release3(ctx);
  return out;
}

/* (connect-poll FD): #f while the connect of socket FD is under way; once
 * it is done, (in out) on it, or a string saying why it failed, FD then
 * being closed.  Never waits. */
static sexp connect_poll (sexp ctx, sexp self, sexp_sint_t n, sexp fd) {
  struct pollfd p;
  int ready, err = 0;
  socklen_t len = sizeof err;
  sexp_assert_type(ctx, sexp_fixnump, SEXP_FIXNUM, fd);
  p.fd = sexp_unbox_fixnum(fd);
  p.events = POLLOUT;
  ready = poll(&p, 1, 0);
  if (ready == 0 || (ready < 0 && errno == EINTR))
    return SEXP_FALSE;
  /* Writable means done; SO_ERROR says how it ended. */
  if (ready < 0 || getsockopt(p.fd, SOL_SOCKET, SO_ERROR, &err, &len) < 0)
    err = errno;
  if (err == 0)
    return connection_ports(ctx, self, p.fd);
  close(p.fd);
  return reason(ctx, strerror(err));
}

/* (connect-abandon FD): closes socket FD, whose connect took too long. */
static sexp connect_abandon (sexp ctx, sexp self, sexp_sint_t n, sexp fd) {
  sexp_assert_type(ctx, sexp_fixnump, SEXP_FIXNUM, fd);
  close(sexp_unbox_fixnum(fd));
  return SEXP_VOID;
}

sexp sexp_init_library (sexp ctx, sexp self, sexp_sint_t n, sexp env,
                        const char *version, const sexp_abi_identifier_t abi) {
  if (!(sexp_version_compatible(ctx, version, sexp_version)
        && sexp_abi_compatible(ctx, abi, SEXP_ABI_IDENTIFIER)))
    return SEXP_ABI_ERROR;
  sexp_define_foreign(ctx, env, "connect-start", 2, connect_start);
  sexp_define_foreign(ctx, env, "connect-poll", 1, connect_poll);
  sexp_define_foreign(ctx, env, "connect-abandon", 1, connect_abandon);
  return SEXP_VOID;
}
