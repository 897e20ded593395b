;;;; A raw peer: the wire protocol of lib/murdoch/wire/frame.scm's header,
;;;; written out by hand so that a test can break it on purpose.

;;> A TCP connection to \var{port} on loopback: (input . output).
(define (raw-connect port)
  (let ((io (open-net-io "127.0.0.1" port)))
    (cons (cadr io) (car (cddr io)))))

(define (raw-send! conn bytes)
  (write-bytevector bytes (cdr conn))
  (flush-output-port (cdr conn)))

(define (raw-close! conn)
  (close-port (car conn))
  (close-port (cdr conn)))

;;> True when the other side closes the connection (reads end of file).
(define (raw-closed? conn)
  (eof-object? (guard (e (#t (eof-object))) (read-u8 (car conn)))))

;;> A netstring of \var{mac} (64 hex digits) followed by \var{text}.
(define (framed mac text)
  (let ((out (open-output-bytevector)))
    (write-netstring (string->utf8 (string-append mac text)) out)
    (get-output-bytevector out)))

;;> The MAC of frame \var{count} under \var{key}, for the receiver's \var{nonce}.
(define (frame-mac key nonce count text)
  (hmac-sha256 key (string->utf8 (string-append nonce ":"
                                               (number->string count) ":"
                                               text))))

(define (text-of datum)
  (let ((out (open-output-string)))
    (write-simple datum out)
    (get-output-string out)))

;;> A hello from an address space called intruder, offering \var{nonce}.
(define (hello-text nonce)
  (text-of `(hello intruder "127.0.0.1" 1 ,nonce)))

(define (hello-frame key nonce)
  (framed (frame-mac key "hello" 0 (hello-text nonce)) (hello-text nonce)))

;;> The count-th frame of a connection, \var{datum} MAC'd for \var{nonce}.
(define (counted key nonce count datum)
  (framed (frame-mac key nonce count (text-of datum)) (text-of datum)))

;;> The message of the next frame on \var{conn}, unchecked, or an eof object.
(define (raw-answer conn)
  (let ((payload (guard (e (#t (eof-object)))
                   (read-netstring (car conn) 10000000))))
    (if (eof-object? payload)
        payload
        (let ((text (utf8->string payload)))
          (read (open-input-string (substring text 64 (string-length text))))))))

;;> A connection to \var{port} welcomed after hello: (connection . callee's nonce).
(define (welcomed-raw-connect key port nonce)
  (let ((conn (raw-connect port)))
    (raw-send! conn (hello-frame key nonce))
    (cons conn (list-ref (raw-answer conn) 2))))
