// trainer sources land here
