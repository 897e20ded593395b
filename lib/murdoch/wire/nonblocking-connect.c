/*  nonblocking-connect.c -- the C of (murdoch wire connect), which connect.stub
 *  binds: a TCP connect that does not wait, and the port a listener was given
 *
 *  (chibi net)'s open-net-io connects in blocking mode: a host that drops
 *  our SYN holds the whole process, every green thread, for the kernel's
 *  minutes of retries.  Here the connect is non-blocking, and connect.scm
 *  asks every millisecond whether it is done, sleeping its own thread only.
 *
 *  The socket itself is made, owned and closed in Scheme, as (chibi net)
 *  makes its sockets: Chibi keeps one fileno object per descriptor number
 *  and counts the ports on it, and a fileno made or closed any other way
 *  would upset that count, so that closing a connection's ports would not
 *  close it, or the collector would close its number while a later socket
 *  has it.  This file only starts the connect and looks at how it ended.
 */

#include <chibi/eval.h>
#include <ctype.h>
#include <errno.h>
#include <netdb.h>
#include <poll.h>
#include <stdio.h>
#include <string.h>
#include <netinet/in.h>
#include <sys/socket.h>

/* Why a connect failed, as a Scheme string starting lowercase, so that the
 * caller can put it after "cannot connect to HOST:PORT: ". */
static sexp reason (sexp ctx, const char *text) {
  char buf[128];
  snprintf(buf, sizeof buf, "%s", text);
  buf[0] = tolower((unsigned char)buf[0]);
  return sexp_c_string(ctx, buf, -1);
}

/* The first IPv4 address of host, port; NULL and a reason in *why when
 * there is none.  getaddrinfo may ask DNS, which blocks the process:
 * names in a lab are addresses or in /etc/hosts. */
static struct addrinfo *resolve (sexp ctx, const char *host, long port,
                                  sexp *why) {
  struct addrinfo hints, *found;
  char service[8];
  int err;
  memset(&hints, 0, sizeof hints);
  hints.ai_family = AF_INET;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_NUMERICSERV;
  snprintf(service, sizeof service, "%ld", port);
  err = getaddrinfo(host, service, &hints, &found);
  if (err == 0) return found;
  if (err == EAI_NONAME)
    *why = reason(ctx, "no such host");
  else if (err == EAI_SYSTEM)
    *why = reason(ctx, strerror(errno));
  else
    *why = reason(ctx, gai_strerror(err));
  return NULL;
}

/* (connect-start SOCKET HOST PORT): starts the connect of SOCKET, a
 * non-blocking IPv4 stream socket, to HOST:PORT.  Answers #t when the
 * connect is done or under way, or a string saying why it failed. */
static sexp connect_start (sexp ctx, sexp self, int sock, const char *host,
                           long port) {
  struct addrinfo *addr;
  sexp why = SEXP_FALSE;
  int err;
  if (port < 1 || port > 65535)
    return sexp_user_exception(ctx, self, "not a TCP port",
                               sexp_make_fixnum(port));
  addr = resolve(ctx, host, port, &why);
  if (!addr) return why;
  err = connect(sock, addr->ai_addr, addr->ai_addrlen) < 0
    ? errno : 0;
  freeaddrinfo(addr);
  /* EINTR leaves the connect going on, as EINPROGRESS does. */
  if (err != 0 && err != EINPROGRESS && err != EINTR)
    return reason(ctx, strerror(err));
  return SEXP_TRUE;
}

/* (connect-poll SOCKET): #f while the connect of SOCKET is under way; once
 * it is done, #t, or a string saying why it failed.  Never waits. */
static sexp connect_poll (sexp ctx, int sock) {
  struct pollfd p;
  int ready, err = 0;
  socklen_t len = sizeof err;
  p.fd = sock;
  p.events = POLLOUT;
  ready = poll(&p, 1, 0);
  if (ready == 0 || (ready < 0 && errno == EINTR))
    return SEXP_FALSE;
  /* Writable means done; SO_ERROR says how it ended. */
  if (ready < 0 || getsockopt(p.fd, SOL_SOCKET, SO_ERROR, &err, &len) < 0)
    err = errno;
  return err == 0 ? SEXP_TRUE : reason(ctx, strerror(err));
}

/* (socket-port SOCKET): the local port SOCKET is bound to, as the kernel
 * chose it for a listener bound to port 0; #f when it cannot say. */
static sexp socket_port (int sock) {
  struct sockaddr_in addr;
  socklen_t len = sizeof addr;
  if (getsockname(sock, (struct sockaddr *)&addr, &len) < 0
      || addr.sin_family != AF_INET)
    return SEXP_FALSE;
  return sexp_make_fixnum(ntohs(addr.sin_port));
}
