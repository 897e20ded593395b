;;;; The lab's key, part of (murdoch lab).

(define key-bytes 32)

;;> The lab's key as a bytevector, from its key file, made when missing:
;;> written under a temporary name, mode 0600, and linked into place, so
;;> peers starting at once all take the one that won, never half a file.
(define (lab-key lab)
  (let ((file (lab-path lab (lab-setting lab 'key-file))))
    (if (not (file-exists? file))
        (make-key-file file))
    (let ((hex (call-with-input-file file read-line)))
      (if (or (eof-object? hex) (< (string-length hex) 32))
          (error (string-append "the lab's key file is too short " file)))
      (string->utf8 hex))))

(define (make-key-file file)
  (let ((temp (string-append file "." (number->string (current-process-id))
                             ".new")))
    (let ((fd (open temp (bitwise-ior open/write open/create open/exclusive)
                    #o600)))
      (if (not fd) (error (string-append "cannot create the key file " temp)))
      (let ((out (open-output-file-descriptor fd)))
        (write-string (random-hex key-bytes) out)
        (newline out)
        (close-output-port out)))
    (link-file temp file)               ; fails harmlessly if another won
    (delete-file temp)))

(define (random-hex n)
  (let ((bytes (call-with-port (open-binary-input-file "/dev/urandom")
                 (lambda (in) (read-bytevector n in)))))
    (apply string-append
           (map (lambda (b)
                  (string-append (if (< b 16) "0" "") (number->string b 16)))
                (bytevector->list bytes)))))

(define (bytevector->list bv)
  (let loop ((i (- (bytevector-length bv) 1)) (acc '()))
    (if (< i 0) acc (loop (- i 1) (cons (bytevector-u8-ref bv i) acc)))))
