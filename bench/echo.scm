;;;; The bare Chibi echo server, the floor of the benches' round trip,
;;;; fan-out and pipelined throughput, and of bench/stages.scm's whole
;;;; message.

;;> Accepts one connection on \var{listener}, which listens on
;;> 127.0.0.1:\var{port}, and writes each netstring of up to
;;> \var{max-frame} bytes back until the peer closes.  With
;;> \var{blocking?}, a read that finds nothing waits in the kernel, as in
;;> C, not in Chibi's scheduler.  With \var{group-socket}, a socket on a
;;> multicast group (open-multicast-socket), a thread of its own also
;;> writes each datagram sent there back on the connection, as a netstring.
(define (echo-connection listener port blocking? max-frame . group-socket)
  (let* ((addr (get-address-info "127.0.0.1" port))
         (sock (accept listener (address-info-address addr)
                       (address-info-address-length addr)))
         (in (open-input-file-descriptor sock))
         (out (open-output-file-descriptor sock)))
    (if blocking?
        (set-file-descriptor-status!
         sock (bitwise-and (get-file-descriptor-status sock)
                           (bitwise-not open/non-block))))
    (when (and (pair? group-socket) (car group-socket))
      ;; Sent at once (TCP_NODELAY, 1): the sender writes nothing before
      ;; the next answer, so it delays its acknowledgement of an echo up to
      ;; 40 ms, and Nagle's rule would hold the answer as long.
      (set-socket-option! sock ip-proto/tcp 1 1)
      (thread-start! (make-thread (lambda ()
                                    (echo-datagrams (car group-socket) out max-frame)))))
    (let loop ()
      (let ((frame (read-netstring in max-frame)))
        (unless (eof-object? frame)
          (write-netstring frame out)
          (flush-output-port out)
          (loop))))))

(define (echo-datagrams sock out max-frame)
  (let ((buffer (make-bytevector max-frame)))
    (let loop ()
      (let ((n (receive! sock buffer)))
        (when (>= n 0)
          (write-netstring (bytevector-copy buffer 0 n) out)
          (flush-output-port out))
        (loop)))))
